#include "study/sweep_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/plot.h"
#include "core/strings.h"
#include "scenes/knobs.h"

namespace refray::scenes {

namespace fs = std::filesystem;

namespace {

plot::Point timeAndError(const SweepRow& row) { return {row.timing.medianSeconds, row.judged().idiff.rmse, row.run.id}; }

// Rows rendered with one sample per pixel, as a GPU renders a frame.
bool oneSample(const SweepRow& row) { return row.run.knob != "spp" || row.run.value == "1"; }

const SweepRow* defaultsRow(const SweepReport& report) {
    for (const SweepRow& r : report.rows)
        if (r.run.id == "defaults") return &r;
    return nullptr;
}

// The knob's value in a row: the swept value, or the default's for the defaults row.
std::string valueOf(const SweepRow& row, const std::string& knob) {
    if (!row.run.knob.empty()) return row.run.value;
    return knobValue(RenderSettings{}, knob);
}

// Orders values numerically when both are numbers ("float" < "double" by text otherwise).
bool valueLess(const std::string& a, const std::string& b) {
    char* endA = nullptr;
    char* endB = nullptr;
    const double x = std::strtod(a.c_str(), &endA), y = std::strtod(b.c_str(), &endB);
    if (*endA == '\0' && *endB == '\0' && !a.empty() && !b.empty()) return x < y;
    return a > b;  // "float" before "double"
}

std::string fixed(double value, int digits) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, value);
    return text;
}

std::string general(double value, int digits = 4) {
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[64];
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    return text;
}

std::string csvField(const std::string& text) {
    if (text.find_first_of(",\"\n") == std::string::npos) return text;
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

std::string joinedSeconds(const std::vector<double>& seconds) {
    std::string text;
    for (double s : seconds) {
        if (!text.empty()) text += ';';
        text += general(s, 6);
    }
    return text;
}

const KnobInfo& knobInfo(const std::string& name) {
    for (const KnobInfo& k : knobs())
        if (k.name == name) return k;
    return knobs().front();
}

std::string verdictText(const CompareResult& r) { return std::string(toString(r.verdict)); }

}  // namespace

void markParetoFronts(SweepReport& report) {
    const std::vector<size_t> gpuRows = oneSampleRows(report);
    std::vector<plot::Point> all;
    for (size_t i : gpuRows) all.push_back(timeAndError(report.rows[i]));
    for (size_t j : plot::paretoFront(all)) report.rows[gpuRows[j]].onGlobalFront = true;
    for (const SweepKnob& k : report.plan.knobs) {
        const std::vector<size_t> rows = knobRows(report, k.name);
        std::vector<plot::Point> points;
        for (size_t i : rows) points.push_back(timeAndError(report.rows[i]));
        for (size_t j : plot::paretoFront(points))
            if (report.rows[rows[j]].run.id != "defaults") report.rows[rows[j]].onFront = true;
    }
    // The defaults row is on "its" front when no row of any knob dominates it.
    for (SweepRow& r : report.rows)
        if (r.run.id == "defaults") r.onFront = r.onGlobalFront;
}

std::optional<size_t> cheapestPassing(const SweepReport& report) {
    std::optional<size_t> best;
    for (size_t i = 0; i < report.rows.size(); ++i) {
        const SweepRow& r = report.rows[i];
        if (!oneSample(r) || r.numerical.golden.verdict > CompareVerdict::Warn) continue;
        if (!best || r.timing.medianSeconds < report.rows[*best].timing.medianSeconds) best = i;
    }
    return best;
}

std::vector<size_t> oneSampleRows(const SweepReport& report) {
    std::vector<size_t> rows;
    for (size_t i = 0; i < report.rows.size(); ++i)
        if (oneSample(report.rows[i])) rows.push_back(i);
    return rows;
}

std::vector<size_t> knobRows(const SweepReport& report, const std::string& knob) {
    std::vector<size_t> rows;
    for (size_t i = 0; i < report.rows.size(); ++i)
        if (report.rows[i].run.knob == knob || report.rows[i].run.id == "defaults") rows.push_back(i);
    std::stable_sort(rows.begin(), rows.end(), [&](size_t a, size_t b) {
        return valueLess(valueOf(report.rows[a], knob), valueOf(report.rows[b], knob));
    });
    return rows;
}

std::string sweepCsv(const SweepReport& report) {
    const SweepRow* defaults = defaultsRow(report);
    const double base = defaults ? defaults->timing.medianSeconds : 0.0;
    std::ostringstream out;
    out << "id,knob,value,settings,median_seconds,time_vs_defaults,seconds,threads,host,warnings,same_sampling_reference";
    for (const char* against : {"total", "numerical"})
        for (const char* column : {"rmse", "psnr_db", "flip_mean", "flip_max", "max_abs_error", "percent_over_idiff_fail",
                                   "percent_over_golden_fail", "golden_verdict"})
            out << ',' << against << '_' << column;
    out << ",on_knob_front,on_global_front\n";
    for (const SweepRow& r : report.rows) {
        out << csvField(r.run.id) << ',' << r.run.knob << ',' << csvField(r.run.value) << ',' << csvField(r.run.settings)
            << ',' << general(r.timing.medianSeconds, 6) << ',' << (base > 0 ? general(r.timing.medianSeconds / base, 4) : "")
            << ',' << joinedSeconds(r.timing.seconds) << ',' << r.timing.threads << ',' << csvField(r.timing.host) << ','
            << r.timing.warnings << ',' << r.run.sameSamplingReference;
        for (const SweepError* e : {&r.total, &r.numerical})
            out << ',' << general(e->idiff.rmse, 6) << ',' << general(e->idiff.psnr, 5) << ','
                << general(e->idiff.flip.mean, 5) << ',' << general(e->idiff.flip.max, 5) << ','
                << general(e->idiff.maxError.value, 5) << ',' << general(e->idiff.failingPercent(), 5) << ','
                << general(e->golden.failingPercent(), 5) << ',' << verdictText(e->golden);
        out << ',' << (r.onFront ? 1 : 0) << ',' << (r.onGlobalFront ? 1 : 0) << '\n';
    }
    return out.str();
}

std::string sweepMarkdown(const SweepReport& report) {
    const SweepPlan& plan = report.plan;
    const SweepRow* defaults = defaultsRow(report);
    const double base = defaults ? defaults->timing.medianSeconds : 0.0;
    std::ostringstream md;
    md << "# Accuracy sweep: " << plan.scene.filename().string();
    if (!plan.camera.empty()) md << ", camera `" << plan.camera << "`";
    md << "\n\n";
    md << "- Camera: " << (plan.camera.empty() ? "the scene's default" : "`" + plan.camera + "`") << "; size "
       << plan.width << "x" << plan.height;
    if (plan.time) md << "; time " << general(*plan.time, 6) << " s";
    md << "\n- Timing: median of " << plan.repeats << " renders per setting, " << plan.threads << " threads";
    if (defaults) md << ", host `" << defaults->timing.host << "`";
    md << "\n- Reference: `" << plan.reference << "`, rendered once in " << fixed(report.referenceTiming.medianSeconds, 2)
       << " s. Each row is also compared with the reference's numerical settings at the row's own samples per pixel "
          "(the same-sampling reference), which leaves out the sampling error.\n";
    md << "- **total** error: against the reference (sampling and numerical error). **numerical** error: against the "
          "same-sampling reference (what steps, thresholds, iterations, epsilons, depth and precision leave). RMSE, "
          "PSNR and mean LDR-FLIP over RGB, as `refray compare` computes them; \"> 1e-6\" is the share of pixels over "
          "idiff's default fail threshold, \"> 0.005\" over the `--golden` profile's, which passes an image with up "
          "to 0.1 % of such pixels.\n\n";

    md << "## Golden settings\n\n";
    if (report.goldenSearchStart) {
        const GoldenSearchStep& start = *report.goldenSearchStart;
        const GoldenSearchStep* result = &start;
        for (const GoldenSearchStep& g : report.goldenSearch)
            if (g.passes) result = &g;
        md << "A golden is compared with one GPU frame, so it is rendered with one sample per pixel. The golden search "
              "(`--golden-search`) starts from the reference's settings at one sample per pixel and relaxes one knob "
              "at a time towards its default, keeping each value whose render still passes `refray compare --golden` "
              "against the one-sample reference:\n\n";
        md << "| step | tried | setting | median s | x defaults | numerical RMSE | > 0.005 % | --golden | kept |\n";
        md << "|---|---|---|---|---|---|---|---|---|\n";
        auto stepRow = [&](size_t n, const GoldenSearchStep& g) {
            md << "| " << n << " | " << (g.knob.empty() ? "start" : "`" + g.knob + "=" + g.value + "`") << " | `"
               << g.settings << "` | " << fixed(g.timing.medianSeconds, 3) << " | "
               << (base > 0 ? fixed(g.timing.medianSeconds / base, 2) : "") << " | " << general(g.error.idiff.rmse) << " | "
               << general(g.error.golden.failingPercent(), 3) << " | " << verdictText(g.error.golden) << " | "
               << (g.knob.empty() ? "" : g.passes ? "yes" : "no") << " |\n";
        };
        stepRow(0, start);
        for (size_t i = 0; i < report.goldenSearch.size(); ++i) stepRow(i + 1, report.goldenSearch[i]);
        md << "\n**Golden settings: `" << report.goldenSearchResult << "`**, " << fixed(result->timing.medianSeconds, 3)
           << " s";
        if (base > 0) md << " (" << fixed(result->timing.medianSeconds / base, 2) << "x the defaults' time)";
        md << ". The search is greedy: it finds a cheap passing setting, not necessarily the cheapest of all "
              "combinations.\n\n";
    } else if (report.goldenSettings) {
        const SweepRow& g = report.rows[*report.goldenSettings];
        md << "A golden is compared with one GPU frame, so it is rendered with one sample per pixel. The cheapest such "
              "setting that passes `refray compare --golden` against the one-sample reference: **`"
           << g.run.settings << "`**, " << fixed(g.timing.medianSeconds, 3) << " s";
        if (base > 0) md << " (" << fixed(g.timing.medianSeconds / base, 2) << "x the defaults' time)";
        md << ", numerical RMSE " << general(g.numerical.idiff.rmse) << ", "
           << general(g.numerical.golden.failingPercent(), 3) << " % of pixels over 0.005.\n\n";
    } else {
        md << "No swept setting with one sample per pixel passes `refray compare --golden` against the one-sample "
              "reference: each differs by more than 0.005 on over 0.1 % of the pixels. The knobs were swept one at a "
              "time; try several raised together (e.g. `--knob precision=double` with a larger `steps`).\n\n";
    }

    md << "## Where the defaults sit\n\n";
    if (defaults) {
        md << "Defaults (the HLSL's constants, float, 1 sample per pixel): " << fixed(base, 3) << " s; numerical RMSE "
           << general(defaults->numerical.idiff.rmse) << " (" << general(defaults->numerical.golden.failingPercent(), 3)
           << " % of pixels over 0.005, `--golden` " << verdictText(defaults->numerical.golden) << "); total RMSE "
           << general(defaults->total.idiff.rmse) << ", PSNR " << fixed(defaults->total.idiff.psnr, 1) << " dB.\n\n";
        if (report.floatAgainstDouble) {
            const SweepError& e = *report.floatAgainstDouble;
            md << "Float rounding alone (the defaults against the same settings in double): RMSE " << general(e.idiff.rmse)
               << ", " << general(e.golden.failingPercent(), 3) << " % of pixels over 0.005, largest difference "
               << general(e.idiff.maxError.value, 3) << ", `--golden` " << verdictText(e.golden)
               << ". A GPU's float arithmetic differs from refray's in the same way (other transcendentals, other "
                  "operation order), so expect a GPU render to differ from a golden by about this much.\n\n";
        }
        std::vector<const SweepRow*> dominating;
        const double error = defaults->numerical.idiff.rmse;
        for (size_t i : oneSampleRows(report)) {
            const SweepRow& r = report.rows[i];
            // Timing noise is a few per cent: at most 5 % slower counts as a tie, and better means over 5 % faster or
            // over 10 % less error.
            const bool notWorse = r.timing.medianSeconds <= 1.05 * base && r.numerical.idiff.rmse <= error;
            const bool better = r.timing.medianSeconds < 0.95 * base || r.numerical.idiff.rmse < 0.9 * error;
            if (&r != defaults && notWorse && better) dominating.push_back(&r);
        }
        if (dominating.empty()) {
            md << "They are on the Pareto front of time against numerical RMSE: no swept one-sample setting is clearly "
                  "faster (over 5 %) or clearly more accurate (over 10 % less RMSE) without being worse on the other.\n\n";
        } else {
            md << "They are **not** on the front of time against numerical RMSE. These settings are clearly faster "
                  "(over 5 %) or clearly more accurate (over 10 % less RMSE) without being worse on the other (within "
                  "5 % on time counts as a tie: timing noise on this machine is a few per cent):\n\n";
            for (const SweepRow* r : dominating)
                md << "- `" << r->run.settings << "`: " << fixed(r->timing.medianSeconds, 3) << " s ("
                   << fixed(r->timing.medianSeconds / base, 2) << "x), numerical RMSE " << general(r->numerical.idiff.rmse)
                   << "\n";
            md << "\n";
        }
    }

    for (const SweepKnob& k : plan.knobs) {
        const KnobInfo& info = knobInfo(k.name);
        const bool sampling = k.name == "spp";
        md << "## " << k.name << "\n\n" << info.description << ". The plot shows " << (sampling ? "total" : "numerical")
           << " RMSE against median time; the dashed line is the Pareto front.\n\n";
        md << "![" << k.name << ": RMSE against time](plots/" << k.name << ".png)\n\n";
        md << "| " << k.name << " | median s | x defaults | numerical RMSE | > 1e-6 % | > 0.005 % | --golden | total RMSE "
              "| total PSNR dB | total mean FLIP | front |\n";
        md << "|---|---|---|---|---|---|---|---|---|---|---|\n";
        for (size_t i : knobRows(report, k.name)) {
            const SweepRow& r = report.rows[i];
            md << "| " << valueOf(r, k.name) << (r.run.id == "defaults" ? " (default)" : "") << " | "
               << fixed(r.timing.medianSeconds, 3) << " | " << (base > 0 ? fixed(r.timing.medianSeconds / base, 2) : "")
               << " | " << general(r.numerical.idiff.rmse) << " | " << general(r.numerical.idiff.failingPercent(), 3)
               << " | " << general(r.numerical.golden.failingPercent(), 3) << " | " << verdictText(r.numerical.golden)
               << " | " << general(r.total.idiff.rmse) << " | " << fixed(r.total.idiff.psnr, 1) << " | "
               << general(r.total.idiff.flip.mean, 3) << " | " << (r.onFront ? "yes" : "") << " |\n";
        }
        md << "\n";
    }
    if (!report.missing.empty()) md << "## Missing runs\n\nNo result yet for: " << joined(report.missing) << ".\n\n";
    md << "Every one-sample setting on one plot (numerical RMSE against time):\n\n![every setting](plots/all.png)\n";
    return md.str();
}

std::vector<fs::path> writeSweepPlots(const fs::path& dir, const SweepReport& report) {
    fs::create_directories(dir / "plots");
    std::vector<fs::path> written;
    const SweepRow* defaults = defaultsRow(report);
    const std::string scene = report.plan.scene.stem().string();
    auto plotSpec = [&](const std::string& title) {
        plot::PlotSpec spec;
        spec.title = title;
        spec.xLabel = "median render time (s, " + std::to_string(report.plan.threads) + " threads)";
        spec.yLabel = "numerical RMSE (vs the same-sampling reference)";
        spec.logX = true;
        spec.logY = true;
        if (defaults) spec.highlights.push_back({defaults->timing.medianSeconds, defaults->numerical.idiff.rmse, "defaults"});
        return spec;
    };
    auto frontOf = [&](const std::vector<size_t>& rows) {
        std::vector<plot::Point> points;
        for (size_t i : rows) points.push_back(timeAndError(report.rows[i]));
        std::vector<plot::Point> front;
        for (size_t j : plot::paretoFront(points)) front.push_back(points[j]);
        return front;
    };

    for (size_t k = 0; k < report.plan.knobs.size(); ++k) {
        const std::string& name = report.plan.knobs[k].name;
        plot::PlotSpec spec = plotSpec(scene + ": " + name);
        if (name == "spp") {  // sampling error: against the supersampled reference
            spec.yLabel = "total RMSE (vs the reference)";
            spec.highlights = {{defaults->timing.medianSeconds, defaults->total.idiff.rmse, "defaults"}};
        }
        plot::Series series;
        series.name = name;
        series.colour = plot::seriesColour(k);
        series.labelPoints = true;
        const std::vector<size_t> rows = knobRows(report, name);
        for (size_t i : rows) {
            plot::Point p = timeAndError(report.rows[i]);
            p.label = valueOf(report.rows[i], name);
            series.points.push_back(p);
        }
        spec.series.push_back(std::move(series));
        spec.front = frontOf(rows);
        const fs::path path = fs::path("plots") / (name + ".png");
        writeImage((dir / path).string(), plot::renderPlot(spec));
        written.push_back(path);
    }

    plot::PlotSpec all = plotSpec(scene + ": every one-sample setting");
    for (size_t k = 0; k < report.plan.knobs.size(); ++k) {
        if (report.plan.knobs[k].name == "spp") continue;
        plot::Series series;
        series.name = report.plan.knobs[k].name;
        series.colour = plot::seriesColour(k);
        series.marker = plot::Marker(k % 4);
        for (size_t i : knobRows(report, series.name)) series.points.push_back(timeAndError(report.rows[i]));
        all.series.push_back(std::move(series));
    }
    all.front = frontOf(oneSampleRows(report));
    const fs::path path = fs::path("plots") / "all.png";
    writeImage((dir / path).string(), plot::renderPlot(all));
    written.push_back(path);
    return written;
}

}  // namespace refray::scenes
