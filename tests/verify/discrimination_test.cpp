// The golden discrimination suite at the goldens' size (issue 17, docs/golden-discrimination.md): against every
// envelope golden of tests/golden, the correct candidates the envelope was not made from must pass, and every
// mutant the doc's 320x180 table records as caught must still fail.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "verify/discrimination.h"
#include "verify/golden.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
const fs::path kRoot = REFRAY_SOURCE_DIR;

// The doc's table under "## At 320x180": the goldens from its header, then per candidate row the goldens whose
// cell starts with FAILURE or "render error" (caught).
std::map<std::string, std::set<std::string>> documentedCatches(std::vector<std::string>& goldens) {
    std::ifstream doc(kRoot / "docs/golden-discrimination.md");
    std::map<std::string, std::set<std::string>> caught;
    bool inSection = false, inTable = false;
    const auto cells = [](const std::string& line) {
        std::vector<std::string> out;
        std::stringstream ss(line.substr(1));
        for (std::string cell; std::getline(ss, cell, '|');) {
            const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
            out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
        }
        return out;
    };
    for (std::string line; std::getline(doc, line);) {
        if (line.rfind("## ", 0) == 0) inSection = line.rfind("## At 320x180", 0) == 0;
        if (!inSection) continue;
        if (line.rfind("| candidate | kind |", 0) == 0) {
            const std::vector<std::string> header = cells(line);
            goldens.assign(header.begin() + 2, header.end());
            inTable = true;
            continue;
        }
        if (!inTable || line.rfind("| `", 0) != 0) {
            if (inTable && line.empty()) inTable = false;
            continue;
        }
        const std::vector<std::string> row = cells(line);
        const std::string name = row[0].substr(1, row[0].size() - 2);
        for (size_t g = 0; g < goldens.size() && g + 2 < row.size(); ++g) {
            std::string cell = row[g + 2];
            if (cell.rfind("**", 0) == 0) cell = cell.substr(2);
            if (cell.rfind("FAILURE", 0) == 0 || cell.rfind("render error", 0) == 0) caught[name].insert(goldens[g]);
        }
    }
    return caught;
}

class Discrimination : public testing::TestWithParam<std::string> {};

TEST_P(Discrimination, CorrectCandidatesPassAndDocumentedCatchesFail) {
    std::vector<std::string> goldens;
    const std::map<std::string, std::set<std::string>> caught = documentedCatches(goldens);
    ASSERT_FALSE(goldens.empty()) << "docs/golden-discrimination.md has no '## At 320x180' table";
    uint64_t catches = 0;
    for (const auto& [name, where] : caught) catches += where.size();
    ASSERT_GE(catches, 20u) << "the doc's 320x180 table records fewer than 20 catches";

    DiscriminationOptions o;
    o.goldenDirectory = kRoot / "tests/golden";
    o.repositoryRoot = kRoot;
    o.threads = 2;
    o.goldens = {GetParam()};
#ifdef REFRAY_FMA_BINARY
    o.fusedRefray = REFRAY_FMA_BINARY;
#endif
    // Whether the table records mutant `name` as caught on `golden`.
    const auto caughtOn = [&caught](const std::string& name, const std::string& golden) {
        const auto documented = caught.find(name);
        return documented != caught.end() && documented->second.contains(golden);
    };
    // Only what the test judges: every correct candidate and the mutants the table records as caught on this
    // golden (a mutant it records as passing here is rendered by the report, not by the test).
    for (const DiscriminationCandidate& c : discriminationCandidates()) {
        const bool judged = c.kind == CandidateKind::Correct || caughtOn(c.name, GetParam());
#if defined(__SANITIZE_ADDRESS__)
        // Perturbed renders cost ten times a nominal one, and ten times more under the sanitizers: one unseen seed.
        if (c.name.rfind("perturbed-seed-", 0) == 0 && c.name != "perturbed-seed-9") continue;
#endif
        if (judged) o.only.push_back(c.name);
    }
    const std::vector<DiscriminationRow> rows = runDiscrimination(o);
    ASSERT_FALSE(rows.empty());
    for (const DiscriminationRow& r : rows) {
        SCOPED_TRACE(r.candidate.name);
        if (r.candidate.kind == CandidateKind::Correct) {
            if (r.unavailable) {
                std::printf("%s: %s not run: %s\n", r.golden.c_str(), r.candidate.name.c_str(), r.error.c_str());
                continue;
            }
            EXPECT_TRUE(r.ran) << r.golden << ": " << r.error;
            EXPECT_NE(r.judgement.verdict, CompareVerdict::Fail)
                << r.golden << ": the correct candidate " << r.candidate.name << " (" << r.candidate.how
                << ") fails: a false alarm\n"
                << r.judgement.describe();
            continue;
        }
        if (!caughtOn(r.candidate.name, r.golden)) continue;
        EXPECT_TRUE(outcomeAsExpected(r)) << r.golden << ": the mutant " << r.candidate.name << " ("
                                          << r.candidate.what << ") is caught in docs/golden-discrimination.md but "
                                          << outcomeName(r) << " now\n"
                                          << (r.ran ? r.judgement.describe() : r.error);
    }
}

std::vector<std::string> goldenNames() {
    std::vector<std::string> names;
    for (const GoldenEntry& e : readGoldenManifest(kRoot / "tests/golden/goldens.json").entries) names.push_back(e.name);
    return names;
}

INSTANTIATE_TEST_SUITE_P(EveryGolden, Discrimination, testing::ValuesIn(goldenNames()),
                         [](const testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

}  // namespace
}  // namespace refray::scenes
