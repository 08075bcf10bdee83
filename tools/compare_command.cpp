#include "tools/compare_command.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
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
    sub->add_option("reference", o.reference, "Reference image; ref-*.ext beside it are accepted variants")->required();
    sub->add_option("candidate", o.candidate, "Candidate image (e.g. your GPU back end's render)")->required();
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
    sub->add_flag("--golden", o.golden,
                  "Tolerances for a GPU render against a refray golden PNG: --fail 0.005 --failpercent 0.1 --warn 0.005");
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
    sub->callback([&o, fail, failPercent, hardFail, warn, warnPercent, hardWarn, thresholdOnly, statisticalOnly] {
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

}  // namespace

int runCompare(const CompareCommandOptions& o) {
    if (o.statistical) return runStatisticalCompare(o);
    try {
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
                    rows.push_back({referencePaths[i], o.candidate, &references[i], &candidate, &results[i], i == best});
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

void writeCompareReport(const std::string& path, CompareVerdict overall, const std::string& summary,
                        std::vector<CompareReportRow> rows) {
    // Failing rows first, as Blender's render-test report does; otherwise in given order.
    std::stable_sort(rows.begin(), rows.end(), [](const CompareReportRow& a, const CompareReportRow& b) {
        return a.result->verdict > b.result->verdict;
    });

    std::ostringstream html;
    const std::string verdict(toString(overall));
    html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>refray compare: " << verdict
         << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
    html << "<h1>refray compare: <span id=\"verdict\" class=\"badge " << verdict << "\">" << verdict << "</span></h1>\n";
    html << "<p id=\"summary\">" << htmlEscape(summary) << "</p>\n";
    html << "<p>Hover over a candidate to see the reference in its place. Diffs are heat maps through the magma "
            "ramp: black is no difference, pale yellow the largest.</p>\n";
    html << "<table id=\"comparisons\">\n<thead><tr><th>reference</th><th>candidate</th><th>diff</th><th>numbers</th>"
            "</tr></thead>\n<tbody>\n";
    for (const CompareReportRow& row : rows) {
        const std::string rowVerdict(toString(row.result->verdict));
        html << "<tr class=\"comparison " << rowVerdict << "\" data-verdict=\"" << rowVerdict << "\" data-reference=\""
             << htmlEscape(row.referencePath) << "\">\n";
        html << "<td>" << imageTag("reference", *row.reference, "reference " + row.referencePath)
             << "<div class=\"caption\">" << htmlEscape(row.referencePath) << "</div></td>\n";
        html << "<td>" << imageTag("candidate", *row.candidate, "candidate " + row.candidatePath)
             << "<div class=\"caption\">" << htmlEscape(row.candidatePath)
             << "</div><div class=\"caption showing\">showing: candidate</div></td>\n";
        html << "<td>";
        if (row.result->diffImage.empty()) html << "<div class=\"caption\">no diff: " << htmlEscape(row.result->mismatch) << "</div>";
        else html << imageTag("diff", row.result->diffImage, "diff") << "<div class=\"caption\">diff</div>";
        html << "</td>\n";
        html << "<td><span class=\"badge row-verdict " << rowVerdict << "\">" << rowVerdict << "</span>"
             << (row.matched ? (row.result->verdict == CompareVerdict::Pass ? " <span class=\"matched\">matched</span>"
                                                                             : " <span class=\"matched\">best match</span>")
                             : "")
             << "<pre>"
             << htmlEscape(row.result->describe()) << "</pre></td>\n</tr>\n";
    }
    html << "</tbody>\n</table>\n<script>" << kScript << "</script>\n</body>\n</html>\n";

    std::ofstream out(path, std::ios::binary);
    REFRAY_CHECK(out, "cannot write the HTML report '" << path << "'");
    out << html.str();
    out.close();
    REFRAY_CHECK(out, "cannot write the HTML report '" << path << "'");
}

}  // namespace refray::tools
