#include "tools/golden_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "core/error.h"
#include "tools/cli_common.h"
#include "verify/discrimination.h"

namespace refray::tools {

namespace fs = std::filesystem;

CLI::App* addDiscriminateCommand(CLI::App& golden, DiscriminateCommandOptions& o) {
    auto* c = golden.add_subcommand(
        "discriminate", "Judge correct candidates and mutants (real back-end bugs) against every golden of a set "
                        "(docs/golden-discrimination.md)");
    c->add_option("dir", o.goldenDirectory, "The golden directory")->capture_default_str();
    c->add_option("--root", o.repositoryRoot, "The repository root: the manifest's scene paths are relative to it")
        ->capture_default_str();
    c->add_option("--fma-refray", o.fmaRefray,
                  "refray built with fused multiply-add (the refray-fma target; default: refray-fma beside this "
                  "binary)");
    c->add_option("--only", o.only, "Run only these candidates (repeatable; names as the report prints them)")
        ->delimiter(',');
    c->add_option("--markdown", o.markdown, "Write the report's tables (Markdown) to FILE");
    c->add_option("--threads", o.threads, "Worker threads (0: all)")->check(threadCount());
    return c;
}

int runDiscriminate(const DiscriminateCommandOptions& o) {
    scenes::DiscriminationOptions options;
    options.goldenDirectory = o.goldenDirectory;
    options.repositoryRoot = o.repositoryRoot;
    options.threads = o.threads;
    options.only = o.only;
    if (!o.fmaRefray.empty()) {
        REFRAY_CHECK(fs::exists(o.fmaRefray), "--fma-refray: no such file '" << o.fmaRefray << "'");
        options.fusedRefray = o.fmaRefray;
    } else {
        std::error_code ec;
        const fs::path self = fs::read_symlink("/proc/self/exe", ec);
        if (!ec && fs::exists(self.parent_path() / "refray-fma")) options.fusedRefray = self.parent_path() / "refray-fma";
    }
    options.onRow = [](const scenes::DiscriminationRow& r) {
        std::printf("%-44s %-26s %-8s %-12s", r.golden.c_str(), r.candidate.name.c_str(),
                    r.candidate.kind == scenes::CandidateKind::Correct ? "correct" : "mutant",
                    scenes::outcomeName(r).c_str());
        if (r.ran)
            std::printf(" stable %llu/%llu  sensitive %llu/%llu  %.1f s", (unsigned long long)r.judgement.stableOutside,
                        (unsigned long long)r.judgement.stableBudget, (unsigned long long)r.judgement.sensitiveOutside,
                        (unsigned long long)r.judgement.sensitiveBudget, r.seconds);
        else
            std::printf(" %s", r.error.c_str());
        if (!r.note.empty()) std::printf("  (%s)", r.note.c_str());
        std::printf("%s\n", scenes::outcomeAsExpected(r) ? "" : "   <- not as expected");
        std::fflush(stdout);
    };
    const std::vector<scenes::DiscriminationRow> rows = scenes::runDiscrimination(options);
    const std::string markdown = scenes::discriminationMarkdown(rows);
    if (!o.markdown.empty()) {
        std::ofstream out(o.markdown);
        REFRAY_CHECK(out << markdown, "cannot write '" << o.markdown << "'");
    }
    bool falseAlarm = false, missed = false;
    for (const scenes::DiscriminationRow& r : rows) {
        if (scenes::outcomeAsExpected(r)) continue;
        if (r.candidate.kind == scenes::CandidateKind::Correct) falseAlarm = falseAlarm || r.ran;
        else missed = true;
    }
    std::printf("\n%s", markdown.substr(0, markdown.find("\n\n")).c_str());
    std::printf("\n");
    return falseAlarm ? 2 : missed ? 1 : 0;
}

}  // namespace refray::tools
