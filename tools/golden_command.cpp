#include "tools/golden_command.h"

#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "tools/cli_common.h"
#include "tools/version.h"
#include "verify/discrimination.h"
#include "verify/golden.h"

namespace refray::tools {

namespace fs = std::filesystem;

static_assert(GoldenCommandOptions{}.update.perturbed == scenes::kDefaultPerturbedRenders &&
              GoldenCommandOptions{}.make.perturbed == scenes::kDefaultPerturbedRenders);

namespace {

// Fewer perturbed renders calibrate nothing: K = 3 is the least that draws each contraction mode (mixed, split, fuse)
// and both denormal modes once (scenes::goldenPerturbation) and leaves two others for each leave-one-out count.
constexpr uint32_t kMinPerturbedRenders = 3;
constexpr const char* kPerturbedAccepts =
    "a number of perturbed renders from 3 to 1000 (fewer cannot calibrate an envelope: each contraction and denormal "
    "mode needs a render, and the leave-one-out counts need two others)";

void printRender(const std::string& what, double seconds) {
    std::printf("    %-28s %7.2f s\n", what.c_str(), seconds);
    std::fflush(stdout);
}

void printEntry(const scenes::GoldenEntry& e) {
    std::printf("%-48s %ux%u  %llu sensitive, %llu order-dependent pixels\n", e.name.c_str(), e.width, e.height,
                (unsigned long long)e.sensitivePixels, (unsigned long long)e.orderDependentPixels);
    std::fflush(stdout);
}

// --emit-jobs: one command line per render of the plan just written into `dir`.
int emitJobs(const GoldenCommandOptions& o, const std::string& file, const std::string& dir, const std::string& collect) {
    const std::vector<std::string> lines =
        scenes::goldenJobCommands(dir, o.repositoryRoot, fs::read_symlink("/proc/self/exe").string());
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    writeTextFile(file, text);
    std::printf("wrote %zu job lines to %s (plan: %s/jobs/plan.json); run them (e.g. 'parallel < %s', or a Slurm "
                "array: README), then: %s\n",
                lines.size(), file.c_str(), dir.c_str(), file.c_str(), collect.c_str());
    return 0;
}

// Shows each scene's build warnings once, as render does; --warnings-as-errors stops at them.
scenes::SceneBuiltCallback sceneWarnings(const GoldenCommandOptions& o, const std::string& command) {
    const bool asErrors = o.warningsAsErrors;
    return [asErrors, command](const scenes::Scene& scene) { reportBuildWarnings(command, scene.buildWarnings(), asErrors); };
}

int runUpdate(const GoldenCommandOptions& o) {
    const auto& u = o.update;
    if (u.collect) {
        REFRAY_CHECK(u.emitJobs.empty(), "--collect and --emit-jobs are separate steps; give one of them");
        const scenes::GoldenSet set = scenes::collectGoldens(u.dir, printEntry);
        std::printf("collected %zu goldens into %s/goldens.json\n", set.entries.size(), u.dir.c_str());
        return 0;
    }
    const Size size = parseSize(u.size);
    scenes::GoldenUpdateOptions options;
    options.repositoryRoot = o.repositoryRoot;
    options.goldenDirectory = u.dir;
    options.width = size.width;
    options.height = size.height;
    options.orders = u.orders;
    options.threads = u.threads;
    options.perturbedRenders = u.perturbed;
    options.refrayCommit = kCommit;
    options.onRender = printRender;
    options.onEntry = [](const scenes::GoldenEntry& e, double seconds) {
        std::printf("%-48s %ux%u  %6.2f s  %llu sensitive, %llu order-dependent pixels\n", e.name.c_str(), e.width,
                    e.height, seconds, (unsigned long long)e.sensitivePixels,
                    (unsigned long long)e.orderDependentPixels);
        std::fflush(stdout);
    };
    options.onSceneBuilt = sceneWarnings(o, "golden update");
    options.onStatisticalEntry = [](const scenes::StatisticalGoldenEntry& e, double seconds) {
        std::printf("%-48s %ux%u  %6.2f s  statistical: %u batches of %u spp\n", e.name.c_str(), e.width, e.height,
                    seconds, e.batches, e.spp);
        std::fflush(stdout);
    };
    checkOutputs({}, {{"--emit-jobs", u.emitJobs}, {"goldens.json (in --dir)", (fs::path(u.dir) / "goldens.json").string()}});
    if (!u.emitJobs.empty()) {
        scenes::writeGoldenPlan(u.dir, scenes::planUpdate(options), true);
        return emitJobs(o, u.emitJobs, u.dir, "refray golden update --collect --dir " + u.dir);
    }
    const scenes::GoldenSet set = scenes::updateGoldens(options);
    std::printf("wrote %zu goldens and %s/goldens.json\n", set.entries.size(), u.dir.c_str());
    return 0;
}

int runMake(const GoldenCommandOptions& o) {
    const auto& m = o.make;
    if (m.collect) {
        REFRAY_CHECK(m.scene.empty() && m.emitJobs.empty(),
                     "--collect reads the plan in " << m.dir << "/jobs; give no scene and no --emit-jobs");
        const scenes::GoldenSet set = scenes::collectGoldens(m.dir, printEntry);
        std::printf("collected %s/goldens.json (%zu goldens)\n", m.dir.c_str(), set.entries.size());
        return 0;
    }
    REFRAY_CHECK(!m.scene.empty(), "refray golden make needs a scene file (or --collect)");
    const Size size = parseSize(m.size);
    scenes::GoldenMakeOptions options;
    options.sceneFile = m.scene;
    options.repositoryRoot = o.repositoryRoot;
    options.goldenDirectory = m.dir;
    options.camera = m.camera;
    options.time = m.time;
    options.width = size.width;
    options.height = size.height;
    options.orders = m.orders;
    options.perturbedRenders = m.perturbed;
    options.refrayCommit = kCommit;
    options.render.threads = m.threads;
    options.render.onRender = printRender;
    options.onSceneBuilt = sceneWarnings(o, "golden make");
    checkOutputs({{"scene file", m.scene}}, {{"--emit-jobs", m.emitJobs}, {"goldens.json (in -o)", (fs::path(m.dir) / "goldens.json").string()}});
    if (!m.emitJobs.empty()) {
        scenes::writeGoldenPlan(m.dir, {scenes::planMake(options)}, false);
        return emitJobs(o, m.emitJobs, m.dir, "refray golden make --collect -o " + m.dir);
    }
    const scenes::GoldenEntry e = scenes::makeGolden(options);
    std::printf("wrote %s/%s (%llu sensitive, %llu order-dependent pixels) and %s/goldens.json\n", m.dir.c_str(),
                e.envelope.c_str(), (unsigned long long)e.sensitivePixels, (unsigned long long)e.orderDependentPixels,
                m.dir.c_str());
    return 0;
}

int runDiscriminate(const GoldenCommandOptions& o) {
    const auto& d = o.discriminate;
    checkOutputs({{"golden manifest", (fs::path(d.goldenDirectory) / "goldens.json").string()}},
                 {{"--markdown", d.markdown}});
    scenes::DiscriminationOptions options;
    options.goldenDirectory = d.goldenDirectory;
    options.repositoryRoot = o.repositoryRoot;
    options.threads = d.threads;
    options.only = d.only;
    options.goldens = d.goldens;
    if (!d.fmaRefray.empty()) {
        REFRAY_CHECK(fs::exists(d.fmaRefray), "--fma-refray: no such file '" << d.fmaRefray << "'");
        options.fusedRefray = d.fmaRefray;
    } else {
        std::error_code ec;
        const fs::path self = fs::read_symlink("/proc/self/exe", ec);
        if (!ec && fs::exists(self.parent_path() / "refray-fma")) options.fusedRefray = self.parent_path() / "refray-fma";
    }
#ifdef REFRAY_HAVE_VULKAN
    {
        // The 'lavapipe' candidate: this refray, on Mesa's lavapipe (--vulkan-device llvmpipe).
        std::error_code ec;
        const fs::path self = fs::read_symlink("/proc/self/exe", ec);
        if (!ec) options.vulkanRefray = self;
    }
#endif
    options.onRow = [](const scenes::DiscriminationRow& r) {
        std::printf("%-44s %-26s %-8s %-12s", r.golden.c_str(), r.candidate.name.c_str(),
                    r.candidate.kind == scenes::CandidateKind::Correct ? "correct" : "mutant",
                    scenes::outcomeName(r).c_str());
        if (r.ran)
            std::printf(" stable %llu/%llu  sensitive %llu/%llu  %.1f s", (unsigned long long)r.judgement.stableOutside,
                        (unsigned long long)r.judgement.stableBudget, (unsigned long long)r.judgement.sensitiveOutside,
                        (unsigned long long)r.judgement.sensitiveBudget, r.seconds);
        if (r.ran && r.judgement.regional.available)
            std::printf("  regional p %.2g", r.judgement.regional.smallestAdjustedP);
        else
            std::printf(" %s", r.error.c_str());
        if (!r.note.empty()) std::printf("  (%s)", r.note.c_str());
        std::printf("%s\n", scenes::outcomeAsExpected(r) ? "" : "   <- not as expected");
        std::fflush(stdout);
    };
    const std::vector<scenes::DiscriminationRow> rows = scenes::runDiscrimination(options);
    const std::string markdown = scenes::discriminationMarkdown(rows);
    if (!d.markdown.empty()) writeTextFile(d.markdown, markdown);
    bool falseAlarm = false, missed = false;
    for (const scenes::DiscriminationRow& r : rows) {
        if (scenes::outcomeAsExpected(r)) continue;
        if (r.candidate.kind == scenes::CandidateKind::Correct) falseAlarm = falseAlarm || r.ran;
        else missed = true;
    }
    std::printf("\n%s\n", markdown.substr(0, markdown.find("\n\n")).c_str());
    return falseAlarm ? 2 : missed ? 1 : 0;
}

}  // namespace

CLI::App* addGoldenCommand(CLI::App& app, GoldenCommandOptions& o) {
    auto* golden = app.add_subcommand("golden", "Envelope goldens of every scene x camera (tests/golden/) and of any "
                                                "settings (docs/golden-format.md)");
    golden->require_subcommand(1);

    auto& u = o.update;
    auto* update = golden->add_subcommand("update", "Re-render the envelope golden of every scene x camera and the "
                                                    "manifest (docs/golden-format.md)");
    update->add_flag("--warnings-as-errors", o.warningsAsErrors, kWarningsAsErrorsHelp);
    update->add_option("--perturbed", u.perturbed, "Perturbed renders per golden (K: seeds 1..K)")
        ->check(wholeNumber(kPerturbedAccepts, kMinPerturbedRenders, 1000))
        ->capture_default_str();
    update->add_option("--dir", u.dir, "Where the goldens go")->capture_default_str();
    update->add_option("--root", o.repositoryRoot, "The repository root (holds scenes/)")->capture_default_str();
    update->add_option("--size", u.size, "Golden size WIDTHxHEIGHT")->capture_default_str();
    update->add_option("--order-check", u.orders, "Adversarial orders per golden")
        ->check(wholeNumber("a number of adversarial orders per golden"))
        ->capture_default_str();
    update->add_option("--emit-jobs", u.emitJobs,
                       "Plan only: write one command line per render to FILE (for GNU parallel or a Slurm array); "
                       "then 'refray golden update --collect'");
    update->add_flag("--collect", u.collect, "Assemble the goldens from the renders the --emit-jobs lines wrote");
    update->add_option("--threads", u.threads, "Worker threads (0: all)")->check(threadCount())->capture_default_str();
    o.updateCommand = update;

    auto& m = o.make;
    auto* make = golden->add_subcommand("make", "Render the envelope golden of one scene, camera, time and size into a "
                                                "golden directory");
    make->add_option("scene", m.scene, "Scene file (not with --collect)");
    make->add_option("--camera", m.camera, "Camera (default: the scene's first)");
    make->add_option("--time", m.time, "Time in seconds (default: the scene's)")->check(seconds());
    make->add_option("--size", m.size, "WIDTHxHEIGHT")->capture_default_str();
    make->add_option("-o,--dir", m.dir, "The golden directory (goldens.json is created or extended)")->required();
    make->add_option("--root", o.repositoryRoot, "The repository root: scene paths in the manifest are relative to it")
        ->capture_default_str();
    make->add_option("--order-check", m.orders, "Adversarial orders")
        ->check(wholeNumber("a number of adversarial orders"))
        ->capture_default_str();
    make->add_flag("--warnings-as-errors", o.warningsAsErrors, kWarningsAsErrorsHelp);
    make->add_option("--perturbed", m.perturbed, "Perturbed renders (K: seeds 1..K)")
        ->check(wholeNumber(kPerturbedAccepts, kMinPerturbedRenders, 1000))
        ->capture_default_str();
    make->add_option("--threads", m.threads, "Worker threads (0: all)")->check(threadCount());
    make->add_option("--emit-jobs", m.emitJobs,
                     "Plan only: write one command line per render to FILE; then 'refray golden make --collect -o DIR'");
    make->add_flag("--collect", m.collect, "Assemble the golden from the renders the --emit-jobs lines wrote");
    o.makeCommand = make;

    auto& j = o.job;
    auto* job = golden->add_subcommand("job", "Render one render of a planned golden (what --emit-jobs lines run)");
    job->add_option("dir", j.dir, "The golden directory holding jobs/plan.json")->required();
    job->add_option("name", j.name, "The golden's name")->required();
    job->add_option("part", j.part, "nominal, order-N, perturbed-N or double")->required();
    job->add_option("--root", o.repositoryRoot, "The repository root: the plan's scene paths are relative to it")
        ->capture_default_str();
    job->add_option("--threads", j.threads, "Worker threads (0: all)")->check(threadCount());
    job->add_flag("--warnings-as-errors", o.warningsAsErrors, kWarningsAsErrorsHelp);
    o.jobCommand = job;

    auto& d = o.discriminate;
    auto* discriminate = golden->add_subcommand(
        "discriminate", "Judge correct candidates and mutants (real back-end bugs) against every golden of a set "
                        "(docs/golden-discrimination.md)");
    discriminate->add_option("dir", d.goldenDirectory, "The golden directory")->capture_default_str();
    discriminate->add_option("--root", o.repositoryRoot,
                             "The repository root: the manifest's scene paths are relative to it")
        ->capture_default_str();
    discriminate->add_option("--fma-refray", d.fmaRefray,
                             "refray built with fused multiply-add (the refray-fma target; default: refray-fma beside "
                             "this binary)");
    discriminate->add_option("--only", d.only, "Run only these candidates (names as the report prints them)")
        ->delimiter(',');
    discriminate->add_option("--golden", d.goldens, "Judge only these goldens of the set (names as goldens.json gives them)")
        ->delimiter(',');
    discriminate->add_option("--markdown", d.markdown, "Write the report's tables (Markdown) to FILE");
    discriminate->add_option("--threads", d.threads, "Worker threads (0: all)")->check(threadCount());
    o.discriminateCommand = discriminate;
    return golden;
}

int runGolden(const GoldenCommandOptions& o) {
    if (*o.jobCommand) {
        scenes::runGoldenJob(o.job.dir, o.repositoryRoot, o.job.name, o.job.part, o.job.threads,
                             sceneWarnings(o, "golden job"));
        return 0;
    }
    if (*o.updateCommand) return runUpdate(o);
    if (*o.makeCommand) return runMake(o);
    return runDiscriminate(o);
}

}  // namespace refray::tools
