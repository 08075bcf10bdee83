#include "tools/compare_command.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/hash.h"
#include "verify/golden.h"
#include "core/statistical_compare.h"
#include "core/strings.h"
#include "tools/cli_common.h"

namespace refray::tools {

namespace {

constexpr const char* kFooter = R"(Verdicts follow OpenImageIO's idiff. A pixel fails when any compared channel differs
by more than --fail; the image fails when more than --failpercent % of pixels fail, any
channel differs by more than --hardfail, or any value is NaN or infinite. Otherwise it
warns likewise with --warn, --warnpercent and --hardwarn, else it passes. The defaults
are idiff's: any difference over 1e-6 fails.

For a GPU render against a refray golden PNG (both R8G8B8A8_UNORM, 1 step = 1/255):
  refray compare --golden golden.png mine.png
is --fail 0.005 --failpercent 0.1 --warn 0.005: one UNORM step anywhere passes, more
than one step warns in up to 0.1 % of pixels and fails beyond. Options given explicitly
override the profile.

REFERENCE may have platform variants beside it (ref.png, ref-<anything>.png): the
candidate passes if it matches any; the report names the match, or the best one.

Noisy (Monte Carlo) renders: make statistics images (mean and variance of K independent
renders) with 'refray render SCENE --batches K -o ref.exr', then
  refray compare --statistical ref.exr test.exr [--alpha 0.01] [--correction sidak] [--map map.png]
runs Welch's t-test per pixel and channel; the image fails when any p-value is below
alpha corrected for the number of tests, so alpha is the false-alarm probability for the
whole image.

Exit status: 0 pass, 1 warning, 2 failure, 3 size mismatch, 4 file error.
See docs/compare.md.)";

// A number >= 0 (or > 0 when `positive`), "inf" included: CLI11's range validators stop at DBL_MAX.
CLI::Validator numberAtLeastZero(bool positive) {
    if (positive) return number("a number > 0", [](double v) { return v > 0.0; });
    return number("a number >= 0", [](double v) { return v >= 0.0; });
}

bool readStatisticsInto(const std::string& path, StatisticsImage& stats) {
    try {
        stats = readStatisticsImage(path);
        return true;
    } catch (const Error& e) {
        std::fprintf(stderr, "refray compare --statistical: %s\n", e.what());
        return false;
    }
}

bool readInto(const std::string& path, Image& image) {
    try {
        image = readImage(path);
        return true;
    } catch (const Error& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return false;
    }
}

void createParentDirectory(const std::string& path) {
    const auto parent = std::filesystem::path(path).parent_path();
    std::error_code ignored;
    if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
}

std::string verdictLine(const CompareResult& r) {
    std::ostringstream out;
    out.precision(6);
    out << toString(r.verdict);
    if (r.verdict == CompareVerdict::Mismatch) out << " (" << r.mismatch << ")";
    else out << " (" << r.failingPixels << " failing pixels, max error " << r.maxError.value << ")";
    return out.str();
}


// Small images are shown enlarged by a whole factor (pixelated) so single pixels show.
std::string imageTag(const char* cssClass, const Image& image, const std::string& alt) {
    const uint32_t factor = std::max(1u, (256u + image.width() - 1) / std::max(1u, image.width()));
    std::ostringstream out;
    out << "<img class=\"" << cssClass << "\" width=\"" << image.width() * factor << "\" height=\""
        << image.height() * factor << "\" alt=\"" << htmlEscape(alt) << "\" src=\"" << pngDataURI(image) << "\">";
    return out.str();
}

constexpr const char* kStyle = R"(
body { font: 14px system-ui, sans-serif; margin: 1.5em; color: #222; background: #fafafa; }
.badge { padding: 0 .35em; border-radius: 4px; color: #fff; }
.badge.PASS { background: #2e7d32; } .badge.WARNING { background: #e65100; }
.badge.FAILURE, .badge.MISMATCH { background: #c62828; }
table { border-collapse: collapse; }
th, td { padding: 8px 10px; text-align: left; vertical-align: top; border-bottom: 1px solid #ddd; }
tr.PASS > td:first-child { border-left: 6px solid #2e7d32; }
tr.WARNING > td:first-child { border-left: 6px solid #e65100; }
tr.FAILURE > td:first-child, tr.MISMATCH > td:first-child { border-left: 6px solid #c62828; }
img { display: block; image-rendering: pixelated; max-width: 22vw; height: auto; }
img.candidate { cursor: crosshair; }
.caption { font: 12px monospace; color: #555; word-break: break-all; max-width: 22vw; }
pre { margin: .4em 0 0; font-size: 12px; white-space: pre-wrap; }
)";

// Hovering over a candidate swaps in the reference; leaving swaps it back.
constexpr const char* kScript = R"(
for (const candidate of document.querySelectorAll('img.candidate')) {
  const reference = candidate.closest('tr').querySelector('img.reference');
  const label = candidate.parentElement.querySelector('.showing');
  const own = candidate.src;
  candidate.addEventListener('mouseenter', () => { candidate.src = reference.src; label.textContent = 'showing: reference'; });
  candidate.addEventListener('mouseleave', () => { candidate.src = own; label.textContent = 'showing: candidate'; });
}
)";

}  // namespace

CLI::App* addCompareCommand(CLI::App& app, CompareCommandOptions& o) {
    auto* sub = app.add_subcommand("compare", "Compare a render (CANDIDATE) to a golden image (REFERENCE), as idiff does");
    sub->footer(kFooter);
    sub->add_option("reference", o.reference, "Reference image; ref-*.ext beside it are accepted variants (with "
                                              "--golden DIR-or-envelope: the candidate; with --golden-set: the "
                                              "candidates' directory)");
    sub->add_option("candidate", o.candidate, "Candidate image (e.g. your GPU back end's render)");
    CLI::Option* fail = sub->add_option("--fail", o.thresholds.fail, "A pixel fails when a channel differs by more")
                            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* failPercent =
        sub->add_option("--failpercent", o.thresholds.failPercent, "Percent of pixels allowed to fail")
            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* hardFail =
        sub->add_option("--hardfail", o.thresholds.hardFail, "Fail if any channel differs by more than this")
            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* warn = sub->add_option("--warn", o.thresholds.warn, "A pixel warns when a channel differs by more")
                            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* warnPercent =
        sub->add_option("--warnpercent", o.thresholds.warnPercent, "Percent of pixels allowed to warn")
            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* hardWarn =
        sub->add_option("--hardwarn", o.thresholds.hardWarn, "Warn if any channel differs by more than this")
            ->check(numberAtLeastZero(false))->capture_default_str();
    CLI::Option* goldenOption =
        sub->add_option("--golden", o.goldenPath,
                        "An envelope golden (a golden directory, or NAME.envelope.exr) to judge the candidate against; "
                        "alone or with a plain image: the tolerances for a GPU render against a golden PNG: --fail "
                        "0.005 --failpercent 0.1 --warn 0.005")
            ->expected(0, 1);
    sub->add_option("--golden-set", o.goldenSet,
                    "A golden directory: judge every golden in it against CANDIDATES_DIR/<name>.exr or .png");
    sub->add_option("--junit", o.junitPath, "--golden-set: write the verdicts as JUnit XML");
    sub->add_option("--channels", o.channels, "Channels compared: rgb (default; DXR samples' alpha means nothing) or rgba")
        ->check(oneOf({"rgb", "rgba"}));
    sub->add_option("--mask", o.maskPath, "Mask image: pixels with non-zero RGB are order-dependent, reported apart "
                                          "and left out of the verdict");
    sub->add_option("-o,--diff", o.diffPath, "Write a diff heat map (PNG): FLIP error through the magma ramp, "
                                             "black = no visible difference");
    sub->add_option("--diff-mode", o.diffMode, "Diff heat map of 'flip' (default) or 'abs': largest channel "
                                               "|difference| x --diff-scale through magma")
        ->check(oneOf({"flip", "abs"}));
    sub->add_option("--diff-scale", o.diffScale, "Scale of --diff-mode abs")->check(numberAtLeastZero(true))->capture_default_str();
    sub->add_option("--html", o.htmlPath, "Write a self-contained HTML report");
    CLI::Option* ppd = sub->add_option("--ppd", o.pixelsPerDegree, "FLIP's pixels per degree of visual angle")
                           ->check(numberAtLeastZero(true))->capture_default_str();

    sub->add_flag("--statistical", o.statistical,
                  "REFERENCE and CANDIDATE are statistics images of noisy renders (mean and variance, from "
                  "'refray render --batches K'): a Welch t-test per pixel and channel");
    CLI::Option* alpha = sub->add_option("--alpha", o.alpha,
                                         "--statistical: the probability of a false alarm for the whole image")
                             ->check(number("a number between 0 and 1 (exclusive)",
                                            [](double a) { return a > 0.0 && a < 1.0; }))
                             ->capture_default_str();
    CLI::Option* correction =
        sub->add_option("--correction", o.correction,
                        "--statistical: the multiple-comparison correction, sidak (default) or bonferroni")
            ->check(oneOf({"sidak", "bonferroni"}));
    CLI::Option* map = sub->add_option("--map", o.mapPath,
                                       "--statistical: write the failure map (PNG): red where a pixel fails, magenta "
                                       "for NaN or infinity, grey rising with -log10 p elsewhere");

    // Each kind of comparison refuses the other's options, so that none is silently ignored.
    const std::vector<CLI::Option*> thresholdOnly = {
        fail, failPercent, hardFail, warn, warnPercent, hardWarn, sub->get_option("--golden"),
        sub->get_option("--channels"), sub->get_option("--mask"), sub->get_option("--diff"),
        sub->get_option("--diff-mode"), sub->get_option("--diff-scale"), sub->get_option("--html"), ppd};
    const std::vector<CLI::Option*> statisticalOnly = {alpha, correction, map};

    // --golden gives the defaults; thresholds given on the command line win.
    sub->callback([&o, fail, failPercent, hardFail, warn, warnPercent, hardWarn, thresholdOnly, statisticalOnly,
                   goldenOption] {
        o.golden = goldenOption->count() > 0;
        // --golden X CANDIDATE leaves CANDIDATE in the first positional.
        if (!o.goldenPath.empty() || !o.goldenSet.empty()) {
            if (!o.candidate.empty())
                throw CLI::ValidationError(o.goldenSet.empty() ? "--golden" : "--golden-set",
                                           "takes one more argument, the candidate (or the candidates' directory), "
                                           "not two");
            o.candidate = o.reference;
            o.reference.clear();
        }
        if (o.candidate.empty())
            throw CLI::ValidationError("compare", o.goldenSet.empty() ? "needs REFERENCE and CANDIDATE (or --golden "
                                                                        "GOLDEN CANDIDATE)"
                                                                      : "--golden-set needs the candidates' directory");
        if (!o.junitPath.empty() && o.goldenSet.empty()) throw CLI::ValidationError("--junit", "needs --golden-set");
        const auto given = [](const std::vector<CLI::Option*>& options) {
            std::string names;
            for (const CLI::Option* option : options)
                if (option->count()) names += (names.empty() ? "" : ", ") + option->get_name();
            return names;
        };
        if (o.statistical && !given(thresholdOnly).empty())
            throw CLI::ValidationError("--statistical", "cannot be combined with " + given(thresholdOnly) +
                                                            " (options of the threshold comparison); a statistical "
                                                            "comparison takes --alpha, --correction and --map");
        if (!o.statistical && !given(statisticalOnly).empty())
            throw CLI::ValidationError(given(statisticalOnly), "needs --statistical (REFERENCE and CANDIDATE being "
                                                               "statistics images from 'refray render --batches K')");
        if (!o.golden) return;
        const CompareThresholds g = CompareThresholds::golden();
        if (!fail->count()) o.thresholds.fail = g.fail;
        if (!failPercent->count()) o.thresholds.failPercent = g.failPercent;
        if (!hardFail->count()) o.thresholds.hardFail = g.hardFail;
        if (!warn->count()) o.thresholds.warn = g.warn;
        if (!warnPercent->count()) o.thresholds.warnPercent = g.warnPercent;
        if (!hardWarn->count()) o.thresholds.hardWarn = g.hardWarn;
    });
    return sub;
}

namespace {

int runStatisticalCompare(const CompareCommandOptions& o) {
    try {
        StatisticsImage reference, candidate;
        if (!readStatisticsInto(o.reference, reference)) return 4;
        if (!readStatisticsInto(o.candidate, candidate)) return 4;
        StatisticalCompareOptions options;
        options.alpha = o.alpha;
        options.correction =
            o.correction == "bonferroni" ? MultipleComparisonCorrection::Bonferroni : MultipleComparisonCorrection::Sidak;
        const StatisticalCompareResult result = compareStatistics(reference, candidate, options);

        std::printf("Comparing \"%s\" against \"%s\" statistically (Welch's t-test per pixel and channel)\n",
                    o.candidate.c_str(), o.reference.c_str());
        std::fputs(result.describe().c_str(), stdout);
        std::fflush(stdout);

        int status = int(result.verdict);
        if (!o.mapPath.empty()) {
            try {
                if (result.failureMap.empty()) {
                    std::fprintf(stderr, "refray compare: no failure map written: %s\n", result.mismatch.c_str());
                } else {
                    createParentDirectory(o.mapPath);
                    writeImage(o.mapPath, result.failureMap);
                    std::printf("wrote %s\n", o.mapPath.c_str());
                }
            } catch (const Error& e) {
                std::fprintf(stderr, "refray compare: %s\n", e.what());
                status = 4;
            }
        }
        return status;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray compare --statistical: %s\n", e.what());
        return 4;
    }
}


namespace fs = std::filesystem;

// The golden a directory holds for a candidate: by the candidate's name (<name>.png, <name>.exr), or the only one.
struct GoldenFile {
    std::string name, envelopePath;
    std::optional<scenes::GoldenEntry> entry;
};

std::string stemOf(const std::string& path) {
    std::string stem = fs::path(path).filename().string();
    const size_t dot = stem.rfind('.');
    if (dot != std::string::npos) stem.erase(dot);
    if (stem.size() > 9 && stem.ends_with(".envelope")) stem.erase(stem.size() - 9);
    return stem;
}

// A golden whose scene file changed since it was made is refused (the scene file is looked for from the current
// directory and from the repository holding DIR/tests/golden); one whose scene file is not here is judged as is.
void checkSceneUnchanged(const scenes::GoldenEntry& e, const fs::path& directory) {
    for (const fs::path& root : {fs::path("."), directory / ".." / ".."}) {
        const fs::path scene = root / e.scene;
        if (!fs::is_regular_file(scene)) continue;
        const std::string sha = sha256HexOfFile(scene);
        REFRAY_CHECK(sha == e.sceneSha256, "the golden " << e.name << " in " << (directory / "goldens.json").string()
                                                         << " was made from " << scene.string() << " with SHA-256 "
                                                         << e.sceneSha256 << ", and that file has changed (SHA-256 "
                                                         << sha << "): review the change and remake the golden with "
                                                                   "'refray golden update' or 'refray golden make'");
        return;
    }
}

GoldenFile resolveGolden(const std::string& golden, const std::string& candidate) {
    GoldenFile g;
    if (!fs::is_directory(golden)) {
        g.envelopePath = golden;
        g.name = stemOf(golden);
        return g;
    }
    const fs::path manifest = fs::path(golden) / "goldens.json";
    REFRAY_CHECK(fs::exists(manifest), "the golden directory " << golden << " has no goldens.json");
    const scenes::GoldenSet set = scenes::readGoldenManifest(manifest);
    const std::string stem = stemOf(candidate);
    for (const scenes::GoldenEntry& e : set.entries)
        if (e.name == stem || set.entries.size() == 1) g.entry = e;
    if (!g.entry) {
        // No golden of that name: the one golden whose camera the candidate is named after ("julia.png"), if only one.
        std::vector<const scenes::GoldenEntry*> byCamera;
        for (const scenes::GoldenEntry& e : set.entries)
            if (e.camera == stem) byCamera.push_back(&e);
        if (byCamera.size() == 1) g.entry = *byCamera.front();
    }
    if (!g.entry) {
        std::string names;
        for (const scenes::GoldenEntry& e : set.entries) names += (names.empty() ? "" : ", ") + e.name;
        REFRAY_CHECK(false, "no golden in " << manifest.string() << " is named '" << stem << "' (from the candidate "
                                            << candidate << "), nor is one alone made with a camera of that name; it "
                                                            "holds: "
                                            << names << " (name the candidate <golden name>.png or .exr, or pass the "
                                                        "golden's .envelope.exr)");
    }
    checkSceneUnchanged(*g.entry, golden);
    g.name = g.entry->name;
    g.envelopePath = (fs::path(golden) / g.entry->envelope).string();
    return g;
}

int writeEnvelopeOutputs(const CompareCommandOptions& o, const EnvelopeJudgement& j, const Envelope& envelope,
                         const Image& candidate, const std::string& envelopePath) {
    try {
        if (!o.diffPath.empty()) {
            if (j.heatMap.empty()) {
                std::fprintf(stderr, "refray compare: no heat map written: %s\n", j.mismatch.c_str());
            } else {
                createParentDirectory(o.diffPath);
                writeImage(o.diffPath, j.heatMap);
                std::printf("wrote %s\n", o.diffPath.c_str());
            }
        }
        if (!o.htmlPath.empty()) {
            CompareReportRow row;
            row.referencePath = envelopePath;
            row.candidatePath = o.candidate;
            row.reference = &envelope.nominal;
            row.candidate = &candidate;
            row.envelope = &j;
            row.matched = true;
            createParentDirectory(o.htmlPath);
            writeCompareReport(o.htmlPath, j.verdict, "\"" + o.candidate + "\" against the envelope \"" + envelopePath + "\"",
                               {row});
            std::printf("wrote %s\n", o.htmlPath.c_str());
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 4;
    }
    return int(j.verdict);
}

int runEnvelopeCompare(const CompareCommandOptions& o) {
    GoldenFile golden;
    Envelope envelope;
    Image candidate;
    try {
        golden = resolveGolden(o.goldenPath, o.candidate);
        envelope = readEnvelope(golden.envelopePath);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 4;
    }
    if (!readInto(o.candidate, candidate)) return 4;
    const EnvelopeJudgement j = judgeEnvelope(envelope, candidate, o.envelope);
    std::printf("Judging \"%s\" against the envelope golden \"%s\" (%u renders, K = %u perturbed)\n",
                o.candidate.c_str(), golden.envelopePath.c_str(), envelope.variants, envelope.perturbedRenders);
    if (j.verdict == CompareVerdict::Mismatch)
        std::fprintf(stderr, "refray compare: %s is %ux%u, the golden %s is %ux%u\n", o.candidate.c_str(),
                     candidate.width(), candidate.height(), golden.envelopePath.c_str(), envelope.width(),
                     envelope.height());
    std::fputs(j.describe().c_str(), stdout);
    std::fflush(stdout);
    return writeEnvelopeOutputs(o, j, envelope, candidate, golden.envelopePath);
}

std::string xmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') out += ' ';
                else out += c;
        }
    }
    return out;
}

struct SetRow {
    std::string name, envelopePath, candidatePath, problem;  // problem: a missing candidate or unreadable golden
    Envelope envelope;
    Image candidate;
    EnvelopeJudgement judgement;
    double seconds = 0.0;
    CompareVerdict verdict() const { return problem.empty() ? judgement.verdict : CompareVerdict::Fail; }
};

int runGoldenSet(const CompareCommandOptions& o) {
    const fs::path directory = o.goldenSet, manifest = fs::path(o.goldenSet) / "goldens.json";
    scenes::GoldenSet set;
    try {
        REFRAY_CHECK(fs::is_directory(o.goldenSet), "the golden set " << o.goldenSet << " is no directory");
        REFRAY_CHECK(fs::exists(manifest), "the golden directory " << o.goldenSet << " has no goldens.json");
        REFRAY_CHECK(fs::is_directory(o.candidate), "the candidates' directory " << o.candidate << " does not exist");
        set = scenes::readGoldenManifest(manifest);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 4;
    }
    std::vector<SetRow> rows(set.entries.size());
    int status = 0;
    std::printf("Judging %zu candidates in \"%s\" against the envelope goldens of \"%s\"\n", rows.size(),
                o.candidate.c_str(), o.goldenSet.c_str());
    for (size_t i = 0; i < set.entries.size(); ++i) {
        const scenes::GoldenEntry& e = set.entries[i];
        SetRow& r = rows[i];
        const auto start = std::chrono::steady_clock::now();
        r.name = e.name;
        r.envelopePath = (directory / e.envelope).string();
        std::vector<std::string> found;
        for (const char* ext : {".exr", ".png"})
            if (fs::exists(fs::path(o.candidate) / (e.name + ext))) found.push_back((fs::path(o.candidate) / (e.name + ext)).string());
        if (!found.empty()) r.candidatePath = found.front();
        try {
            // Two candidates for one golden: judging either would be a quiet choice.
            REFRAY_CHECK(found.size() < 2, "two candidates, " << found[0] << " and " << found[1]
                                                               << "; keep the one to judge");
            checkSceneUnchanged(e, directory);
            r.envelope = readEnvelope(r.envelopePath);
            if (r.candidatePath.empty()) {
                r.problem = "no candidate: neither " + (fs::path(o.candidate) / (e.name + ".exr")).string() + " nor " +
                            (fs::path(o.candidate) / (e.name + ".png")).string() + " exists";
            } else {
                r.candidate = readImage(r.candidatePath);
                r.judgement = judgeEnvelope(r.envelope, r.candidate, o.envelope);
            }
        } catch (const std::exception& ex) {
            r.problem = ex.what();
            status = std::max(status, 4);
        }
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        status = std::max(status, int(r.verdict()));
        std::printf("  %-48s %s", e.name.c_str(), std::string(toString(r.verdict())).c_str());
        if (!r.problem.empty()) std::printf(": %s", r.problem.c_str());
        else if (r.verdict() == CompareVerdict::Mismatch) std::printf(": %s", r.judgement.mismatch.c_str());
        else
            std::printf(" (stable outside %llu of allowed %llu, sensitive outside %llu of allowed %llu, NaN %llu)",
                        (unsigned long long)r.judgement.stableOutside, (unsigned long long)r.judgement.stableBudget,
                        (unsigned long long)r.judgement.sensitiveOutside,
                        (unsigned long long)r.judgement.sensitiveBudget, (unsigned long long)r.judgement.nonFinite);
        if (r.problem.empty() && r.verdict() != CompareVerdict::Mismatch) {
            // The regional count test: the failing region, or how close the closest came.
            const RegionalJudgement& regional = r.judgement.regional;
            if (!regional.available) std::printf(", regional test not judged (an older envelope)");
            else if (regional.failed()) std::printf(", regional: %s", regional.failing.front().describe().c_str());
            else std::printf(", regional p %.2g", regional.smallestAdjustedP);
        }
        std::printf("\n");
    }
    for (const SetRow& r : rows)
        if (r.verdict() != CompareVerdict::Pass && r.problem.empty()) {
            std::printf("%s against %s:\n", r.candidatePath.c_str(), r.envelopePath.c_str());
            std::fputs(r.judgement.describe().c_str(), stdout);
        }
    const CompareVerdict overall = status >= 2 ? CompareVerdict::Fail : CompareVerdict(status);
    std::printf("verdict %s\n", std::string(toString(overall)).c_str());
    std::fflush(stdout);
    try {
        if (!o.htmlPath.empty()) {
            std::vector<CompareReportRow> report;
            for (const SetRow& r : rows) {
                CompareReportRow row;
                row.referencePath = r.envelopePath;
                row.candidatePath = r.candidatePath.empty() ? "(missing)" : r.candidatePath;
                row.reference = r.envelope.nominal.empty() ? nullptr : &r.envelope.nominal;
                row.candidate = r.candidate.empty() ? nullptr : &r.candidate;
                if (r.problem.empty()) row.envelope = &r.judgement;
                else row.missing = r.problem;
                report.push_back(row);
            }
            createParentDirectory(o.htmlPath);
            writeCompareReport(o.htmlPath, overall,
                               std::to_string(rows.size()) + " goldens of \"" + o.goldenSet + "\" against \"" +
                                   o.candidate + "\"",
                               std::move(report));
            std::printf("wrote %s\n", o.htmlPath.c_str());
        }
        if (!o.junitPath.empty()) {
            size_t failures = 0;
            double total = 0.0;
            for (const SetRow& r : rows) {
                failures += r.verdict() >= CompareVerdict::Fail ? 1 : 0;
                total += r.seconds;
            }
            std::ostringstream xml;
            xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"refray compare --golden-set\" tests=\""
                << rows.size() << "\" failures=\"" << failures << "\" time=\"" << total << "\">\n"
                << "  <testsuite name=\"" << xmlEscape(o.goldenSet) << "\" tests=\"" << rows.size() << "\" failures=\""
                << failures << "\" errors=\"0\" skipped=\"0\" time=\"" << total << "\">\n";
            for (const SetRow& r : rows) {
                xml << "    <testcase classname=\"refray.golden\" name=\"" << xmlEscape(r.name) << "\" time=\""
                    << r.seconds << "\">\n";
                const std::string text = r.problem.empty() ? r.judgement.describe() : r.problem;
                if (r.verdict() >= CompareVerdict::Fail)
                    xml << "      <failure type=\"" << toString(r.verdict()) << "\" message=\"" << toString(r.verdict())
                        << ": " << xmlEscape(r.problem.empty() ? r.candidatePath : r.problem) << "\">"
                        << xmlEscape(text) << "</failure>\n";
                else
                    xml << "      <system-out>" << xmlEscape(text) << "</system-out>\n";
                xml << "    </testcase>\n";
            }
            xml << "  </testsuite>\n</testsuites>\n";
            writeTextFile(o.junitPath, xml.str());
            std::printf("wrote %s\n", o.junitPath.c_str());
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 4;
    }
    return status;
}

}  // namespace

int runCompare(const CompareCommandOptions& given) {
    CompareCommandOptions o = given;
    // Before any work: no output may be an input or another output (exit 2, both named), and every image header is
    // within the pixel budget before any image's pixels are allocated (exit 4, named).
    try {
        std::vector<NamedPath> inputs{{"REFERENCE", o.reference}, {"CANDIDATE", o.candidate}, {"--mask", o.maskPath}};
        if (!o.reference.empty() && fs::is_regular_file(o.reference))
            for (const std::string& variant : referenceVariants(o.reference, o.candidate))
                inputs.push_back({"reference variant", variant});
        // A golden directory's manifest and envelopes, and the candidate images of --golden-set, are inputs too.
        const auto addFilesOf = [&inputs](const std::string& dir, const std::string& role) {
            std::error_code error;
            if (dir.empty() || !fs::is_directory(dir, error)) return;
            for (const auto& f : fs::directory_iterator(dir, error)) {
                const std::string ext = f.path().extension().string();
                if (f.is_regular_file(error) && (ext == ".exr" || ext == ".png" || f.path().filename() == "goldens.json"))
                    inputs.push_back({role, f.path().string()});
            }
        };
        if (!o.goldenPath.empty()) inputs.push_back({"--golden", o.goldenPath});
        addFilesOf(o.goldenPath, "golden file");
        addFilesOf(o.goldenSet, "golden file");
        if (!o.goldenSet.empty()) addFilesOf(o.candidate, "candidate");
        checkOutputs(inputs, {{"-o", o.diffPath}, {"--html", o.htmlPath}, {"--junit", o.junitPath}, {"--map", o.mapPath}});
    } catch (const Error& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 2;
    }
    if (o.goldenSet.empty() && !o.statistical) {
        try {
            for (const std::string& path : {o.reference, o.candidate, o.maskPath})
                if (!path.empty()) readImageHeader(path);
        } catch (const Error& e) {
            std::fprintf(stderr, "refray compare: %s\n", e.what());
            return 4;
        }
    }
    if (!o.goldenSet.empty()) return runGoldenSet(o);
    if (!o.goldenPath.empty()) {
        bool envelope = fs::is_directory(o.goldenPath);
        if (!envelope) {
            try {
                envelope = isEnvelopeFile(o.goldenPath);
            } catch (const std::exception& e) {
                std::fprintf(stderr, "refray compare: %s\n", e.what());
                return 4;
            }
        }
        if (envelope) return runEnvelopeCompare(o);
        o.reference = o.goldenPath;  // a plain golden image: the threshold comparison under --golden's profile
    }
    if (o.statistical) return runStatisticalCompare(o);
    try {
        // Sizes from the headers first: a candidate of another size than its one reference is a mismatch before any
        // pixel is allocated (the HTML report, which shows the images, reads them anyway).
        if (o.htmlPath.empty()) {
            try {
                const std::vector<std::string> variants = referenceVariants(o.reference, o.candidate);
                const ImageHeader c = readImageHeader(o.candidate), r = readImageHeader(variants.front());
                if (variants.size() == 1 && (c.width != r.width || c.height != r.height)) {
                    std::printf("Comparing \"%s\" against \"%s\"\n  size mismatch: reference is %ux%u, candidate is "
                                "%ux%u\n  verdict         MISMATCH\n",
                                o.candidate.c_str(), variants.front().c_str(), r.width, r.height, c.width, c.height);
                    if (!o.diffPath.empty())
                        std::fprintf(stderr, "refray compare: no diff image written: size mismatch\n");
                    return int(CompareVerdict::Mismatch);
                }
            } catch (const Error& e) {
                std::fprintf(stderr, "refray compare: %s\n", e.what());
                return 4;
            }
        }
        // Inputs: any unreadable file is exit 4, named.
        Image candidate, mask;
        if (!readInto(o.candidate, candidate)) return 4;
        if (!o.maskPath.empty() && !readInto(o.maskPath, mask)) return 4;
        std::vector<std::string> referencePaths;
        try {
            referencePaths = referenceVariants(o.reference, o.candidate);
        } catch (const Error& e) {
            std::fprintf(stderr, "refray compare: %s\n", e.what());
            return 4;
        }
        std::vector<Image> references(referencePaths.size());
        for (size_t i = 0; i < referencePaths.size(); ++i)
            if (!readInto(referencePaths[i], references[i])) return 4;

        CompareThresholds thresholds = o.thresholds;
        thresholds.includeAlpha = o.channels == "rgba";
        CompareOptions options;
        options.pixelsPerDegree = o.pixelsPerDegree;
        options.diffMode = o.diffMode == "abs" ? DiffMode::AbsoluteError : DiffMode::Flip;
        options.absoluteErrorScale = o.diffScale;

        std::vector<CompareResult> results;
        for (const Image& reference : references)
            results.push_back(compareImages(reference, candidate, thresholds, o.maskPath.empty() ? nullptr : &mask, options));
        const size_t best = bestMatch(results);
        const CompareResult& result = results[best];

        // Report.
        std::string summary;
        if (results.size() == 1) {
            std::printf("Comparing \"%s\" against \"%s\"\n", o.candidate.c_str(), referencePaths[0].c_str());
            summary = "\"" + o.candidate + "\" against \"" + referencePaths[0] + "\"";
        } else {
            std::printf("Comparing \"%s\" against %zu reference variants:\n", o.candidate.c_str(), results.size());
            for (size_t i = 0; i < results.size(); ++i)
                std::printf("  %-40s %s\n", referencePaths[i].c_str(), verdictLine(results[i]).c_str());
            const bool matched = result.verdict == CompareVerdict::Pass;
            std::printf("%s \"%s\":\n", matched ? "Matched" : "Best match", referencePaths[best].c_str());
            summary = "\"" + o.candidate + "\" against " + std::to_string(results.size()) + " reference variants; " +
                      (matched ? "matched \"" : "best match \"") + referencePaths[best] + "\"";
        }
        std::fputs(result.describe().c_str(), stdout);
        std::fflush(stdout);

        // Outputs.
        int status = int(result.verdict);
        try {
            if (!o.diffPath.empty()) {
                if (result.diffImage.empty()) {
                    std::fprintf(stderr, "refray compare: no diff image written: %s\n", result.mismatch.c_str());
                } else {
                    createParentDirectory(o.diffPath);
                    writeImage(o.diffPath, result.diffImage);
                    std::printf("wrote %s\n", o.diffPath.c_str());
                }
            }
            if (!o.htmlPath.empty()) {
                std::vector<CompareReportRow> rows;
                for (size_t i = 0; i < results.size(); ++i)
                    rows.push_back({referencePaths[i], o.candidate, &references[i], &candidate, &results[i], i == best, nullptr, {}});
                createParentDirectory(o.htmlPath);
                writeCompareReport(o.htmlPath, result.verdict, summary, std::move(rows));
                std::printf("wrote %s\n", o.htmlPath.c_str());
            }
        } catch (const Error& e) {
            std::fprintf(stderr, "refray compare: %s\n", e.what());
            status = 4;
        }
        return status;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray compare: %s\n", e.what());
        return 4;
    }
}

namespace {

CompareVerdict rowVerdictOf(const CompareReportRow& row) {
    if (row.result) return row.result->verdict;
    if (row.envelope) return row.envelope->verdict;
    return CompareVerdict::Fail;
}

std::string imageCell(const char* cls, const Image* image, const std::string& alt) {
    return image ? imageTag(cls, *image, alt) : "<div class=\"caption\">no image</div>";
}

}  // namespace

void writeCompareReport(const std::string& path, CompareVerdict overall, const std::string& summary,
                        std::vector<CompareReportRow> rows) {
    // Failing rows first, as Blender's render-test report does; otherwise in given order.
    std::stable_sort(rows.begin(), rows.end(), [](const CompareReportRow& a, const CompareReportRow& b) {
        return rowVerdictOf(a) > rowVerdictOf(b);
    });

    std::ostringstream html;
    const std::string verdict(toString(overall));
    html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>refray compare: " << verdict
         << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
    html << "<h1>refray compare: <span id=\"verdict\" class=\"badge " << verdict << "\">" << verdict << "</span></h1>\n";
    html << "<p id=\"summary\">" << htmlEscape(summary) << "</p>\n";
    html << "<p>Hover over a candidate to see the reference in its place. Diffs are heat maps through the magma "
            "ramp: black is no difference, pale yellow the largest. Envelope heat maps show the nominal image dimmed, "
            "red where a stable pixel moved, orange to pale yellow where a sensitive pixel left its envelope (farther: "
            "paler), blue for order-dependent pixels outside, magenta for NaN or infinity.</p>\n";
    html << "<table id=\"comparisons\">\n<thead><tr><th>reference</th><th>candidate</th><th>diff</th><th>numbers</th>"
            "</tr></thead>\n<tbody>\n";
    for (const CompareReportRow& row : rows) {
        const CompareVerdict v = rowVerdictOf(row);
        const std::string rowVerdict(toString(v));
        html << "<tr class=\"comparison " << rowVerdict << "\" data-verdict=\"" << rowVerdict << "\" data-reference=\""
             << htmlEscape(row.referencePath) << "\">\n";
        html << "<td>" << imageCell("reference", row.reference, "reference " + row.referencePath)
             << "<div class=\"caption\">" << htmlEscape(row.referencePath) << "</div></td>\n";
        html << "<td>" << imageCell("candidate", row.candidate, "candidate " + row.candidatePath)
             << "<div class=\"caption\">" << htmlEscape(row.candidatePath)
             << "</div><div class=\"caption showing\">showing: candidate</div></td>\n";
        html << "<td>";
        const Image* diff = row.result ? &row.result->diffImage : row.envelope ? &row.envelope->heatMap : nullptr;
        const std::string mismatch = row.result ? row.result->mismatch : row.envelope ? row.envelope->mismatch : row.missing;
        if (!diff || diff->empty()) html << "<div class=\"caption\">no diff: " << htmlEscape(mismatch) << "</div>";
        else html << imageTag("diff", *diff, "diff") << "<div class=\"caption\">" << (row.envelope ? "envelope heat map" : "diff") << "</div>";
        html << "</td>\n";
        const std::string numbers = row.result ? row.result->describe() : row.envelope ? row.envelope->describe() : row.missing;
        html << "<td><span class=\"badge row-verdict " << rowVerdict << "\">" << rowVerdict << "</span>"
             << (row.matched ? (v == CompareVerdict::Pass ? " <span class=\"matched\">matched</span>"
                                                          : " <span class=\"matched\">best match</span>")
                             : "")
             << "<pre>" << htmlEscape(numbers) << "</pre></td>\n</tr>\n";
    }
    html << "</tbody>\n</table>\n<script>" << kScript << "</script>\n</body>\n</html>\n";

    writeTextFile(path, html.str());
}

}  // namespace refray::tools
