// Every rule id of dxr-semantics.md sections 0-13 and 18 is cited by a conformance test name or
// by a line in unobservable_rules_*.md saying why it cannot be observed here.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace {

const std::filesystem::path kTestDir = std::filesystem::path(REFRAY_SOURCE_DIR) / "tests" / "emulator";

std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

TEST(RuleCoverage, EveryRuleIdIsTestedOrExplained) {
    std::set<std::string> rules;
    {
        std::istringstream in(readFile(kTestDir / "rule_ids.txt"));
        std::string line;
        while (std::getline(in, line))
            if (!line.empty() && line[0] != '#') rules.insert(line);
    }
    ASSERT_GT(rules.size(), 150u);

    std::set<std::string> tested, explained;
    const std::regex testName(R"(TEST(?:_F|_P)?\(\s*\w+\s*,\s*([A-Z]+)_(\d+)_)");
    const std::regex explanation(R"(^([A-Z]+-\d+):\s*\S)", std::regex::multiline);
    for (const auto& entry : std::filesystem::directory_iterator(kTestDir)) {
        const std::string name = entry.path().filename().string();
        const std::string text = readFile(entry.path());
        if (name.size() > 9 && name.substr(name.size() - 9) == "_test.cpp") {
            for (std::sregex_iterator it(text.begin(), text.end(), testName), end; it != end; ++it)
                tested.insert((*it)[1].str() + "-" + (*it)[2].str());
        } else if (name.rfind("unobservable_rules", 0) == 0) {
            for (std::sregex_iterator it(text.begin(), text.end(), explanation), end; it != end; ++it)
                explained.insert((*it)[1].str());
        }
    }
    std::string missing;
    for (const auto& rule : rules)
        if (!tested.count(rule) && !explained.count(rule)) missing += " " + rule;
    EXPECT_TRUE(missing.empty()) << "rule ids neither tested nor explained:" << missing;
}
