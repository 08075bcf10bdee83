#include "tools/cli_common.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <thread>
#include <sched.h>
#include <unistd.h>

#include "core/file_input.h"
#include "core/file_output.h"

#include "core/error.h"
#include "core/strings.h"

namespace refray::tools {

namespace {

// "<digits><separator><digits>", each number 1 to 9 digits: the two numbers, or false.
bool parseNumberPair(const std::string& text, char separator, unsigned long& a, unsigned long& b) {
    const size_t at = text.find(separator);
    if (at == std::string::npos) return false;
    const auto number = [](std::string_view digits, unsigned long& value) {
        if (digits.empty() || digits.size() > 9) return false;
        value = 0;
        for (char c : digits) {
            if (c < '0' || c > '9') return false;
            value = value * 10 + unsigned(c - '0');
        }
        return true;
    };
    const std::string_view view(text);
    return number(view.substr(0, at), a) && number(view.substr(at + 1), b);
}

}  // namespace

Size parseSize(const std::string& text, const char* option) {
    unsigned long w = 0, h = 0;
    REFRAY_CHECK(parseNumberPair(text, 'x', w, h), option << " expects WIDTHxHEIGHT (e.g. 640x360), got '" << text << "'");
    REFRAY_CHECK(w > 0 && h > 0 && w <= 16384 && h <= 16384, option << " " << text << " is outside 1x1 .. 16384x16384");
    return {uint32_t(w), uint32_t(h)};
}

void parsePixel(const std::string& text, uint32_t& x, uint32_t& y, const char* option) {
    unsigned long a = 0, b = 0;
    REFRAY_CHECK(parseNumberPair(text, ',', a, b), option << " expects X,Y (e.g. 640,360), got '" << text << "'");
    x = uint32_t(a);
    y = uint32_t(b);
}

namespace {

std::string expects(const std::string& accepts, const std::string& text) {
    return "expects " + accepts + ", got '" + text + "'";
}

// "a", "a or b", "a, b or c".
std::string alternatives(const std::vector<std::string>& names) {
    if (names.size() < 2) return joined(names);
    return joined(std::vector<std::string>(names.begin(), names.end() - 1)) + " or " + names.back();
}

// The option names of `command` as a user types them ("--spp", "-o").
std::vector<std::string> optionNames(const CLI::App& command) {
    std::vector<std::string> names;
    for (const CLI::Option* option : command.get_options()) {
        for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
        for (const std::string& name : option->get_snames()) names.push_back("-" + name);
    }
    return names;
}

// What a command was given and does not take: "unknown option --sp (did you mean '--spp'?)", "unexpected argument
// 'b.json'".
std::string describeExtras(const CLI::App& command) {
    std::vector<std::string> parts;
    for (const std::string& arg : command.remaining()) {
        const bool option = arg.size() > 1 && arg[0] == '-' && !std::isdigit((unsigned char)arg[1]);
        const std::string name = arg.substr(0, arg.find('='));
        parts.push_back(option ? "unknown option " + name + didYouMean(name, optionNames(command))
                               : "unexpected argument '" + arg + "'");
    }
    return joined(parts, "; ");
}

}  // namespace

CLI::Validator wholeNumber(const std::string& accepts, uint64_t min, uint64_t max) {
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            uint64_t value = 0;
            const char* end = text.data() + text.size();
            const auto [stop, error] = std::from_chars(text.data(), end, value);
            if (text.empty() || error != std::errc() || stop != end || value < min || value > max)
                return expects(accepts, text);
            return {};
        },
        "");
}

CLI::Validator number(const std::string& accepts, const std::function<bool(double)>& inRange) {
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || std::isnan(value) || !inRange(value)) return expects(accepts, text);
            return {};
        },
        "");
}

CLI::Validator oneOf(const std::vector<std::string>& names) {
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            if (std::find(names.begin(), names.end(), text) != names.end()) return {};
            return expects(alternatives(names), text) + didYouMean(text, names);
        },
        "");
}

uint32_t maxThreads() {
    // The processors this process may run on (oneTBB's own limit), not every processor of the machine.
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return uint32_t(CPU_COUNT(&set));
    return std::max(1u, std::thread::hardware_concurrency());
}

uint32_t threadsRun(uint32_t requested) { return requested == 0 ? maxThreads() : std::min(requested, maxThreads()); }

CLI::Validator threadCount() {
    return wholeNumber("a number of worker threads from 0 (all) to " + std::to_string(maxThreads()) +
                           " (the hardware threads of this machine)",
                       0, maxThreads());
}

CLI::Validator seconds() {
    return number("a time in seconds", [](double t) { return std::isfinite(t); });
}

int parseErrorStatus(const CLI::App& app, const CLI::ParseError& error) {
    if (dynamic_cast<const CLI::Success*>(&error)) return app.exit(error);  // --help, --version
    // The subcommands given, outermost first; the error is about the last one's options, except for arguments that
    // one before it does not take.
    std::vector<const CLI::App*> chain{&app};
    while (!chain.back()->get_subcommands().empty()) chain.push_back(chain.back()->get_subcommands().back());
    const CLI::App* command = chain.back();
    std::string message = error.what();
    if (dynamic_cast<const CLI::ExtrasError*>(&error)) {
        const auto with =
            std::find_if(chain.begin(), chain.end(), [](const CLI::App* a) { return a->remaining_size() > 0; });
        if (with != chain.end()) {
            command = *with;
            message = describeExtras(*command);
        }
    } else if (dynamic_cast<const CLI::RequiredError*>(&error) && command->get_require_subcommand_min() > 0 &&
               command->get_subcommands().empty()) {
        std::vector<std::string> names;
        for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; }))
            names.push_back(sub->get_name());
        message = "expects a subcommand (" + alternatives(names) + ")";
        const std::vector<std::string> given = command->remaining();
        if (!given.empty()) message += ", got '" + given.front() + "'" + didYouMean(given.front(), names);
    }
    chain.erase(std::find(chain.begin(), chain.end(), command) + 1, chain.end());
    std::string name = "refray";
    for (auto a = chain.begin() + 1; a != chain.end(); ++a) name += " " + (*a)->get_name();
    std::fprintf(stderr, "%s: %s (see '%s --help')\n", name.c_str(), message.c_str(), name.c_str());
    return 2;
}

Progress::Sink terminalProgress() {
    if (!isatty(STDERR_FILENO)) return {};
    return [](const ProgressState& s) {
        std::fprintf(stderr, "\r%s", formatProgressBar(s).c_str());
        if (s.finished) std::fputc('\n', stderr);
        std::fflush(stderr);
    };
}

void writeOutput(const std::string& path, const Image& image) { writeImage(path, image); }

namespace {

// Whether two paths name one file: the same existing file, or (not yet existing) the same absolute path.
bool samePath(const std::string& a, const std::string& b) {
    if (sameFile(a, b)) return true;
    std::error_code error;
    const auto ca = std::filesystem::weakly_canonical(a, error);
    if (error) return false;
    const auto cb = std::filesystem::weakly_canonical(b, error);
    return !error && ca == cb;
}

}  // namespace

void checkOutputs(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
    for (size_t i = 0; i < outputs.size(); ++i) {
        const NamedPath& out = outputs[i];
        if (out.path.empty()) continue;
        for (const NamedPath& in : inputs)
            REFRAY_CHECK(in.path.empty() || !samePath(out.path, in.path),
                         "the output " << out.role << " '" << out.path << "' is the input " << in.role << " '"
                                       << in.path << "'; refray never overwrites an input: give another output file");
        for (size_t j = 0; j < i; ++j)
            REFRAY_CHECK(outputs[j].path.empty() || !samePath(out.path, outputs[j].path),
                         "the outputs " << outputs[j].role << " '" << outputs[j].path << "' and " << out.role << " '"
                                        << out.path << "' are the same file; give each its own name");
        checkOutputPath(out.path);
    }
}

void reportBuildWarnings(const std::string& command, const std::vector<dxr::Diagnostic>& warnings, bool asErrors) {
    for (const dxr::Diagnostic& w : warnings) std::fprintf(stderr, "refray %s: %s\n", command.c_str(), w.format().c_str());
    REFRAY_CHECK(!asErrors || warnings.empty(), "--warnings-as-errors: the scene has " << warnings.size()
                                                                                       << " build warning"
                                                                                       << (warnings.size() == 1 ? "" : "s")
                                                                                       << " (above)");
}

namespace {

std::string base64(const std::string& bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += kAlphabet[v & 63];
    }
    if (i + 1 == bytes.size()) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8;
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

}  // namespace

// Through a temporary file because core/image writes files only.
std::string pngDataURI(const Image& image) {
    static std::atomic<unsigned> counter{0};
    const auto path = std::filesystem::temp_directory_path() /
                      ("refray-page-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + ".png");
    Image bare(image.width(), image.height());
    bare.pixels() = image.pixels();
    writeImage(path.string(), bare);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    in.close();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return "data:image/png;base64," + base64(bytes.str());
}

}  // namespace refray::tools
