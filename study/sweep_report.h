// The report of a sweep (study/sweep.h): Pareto fronts, the golden settings, the CSV, the markdown table and the
// plots of error against time.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "study/sweep.h"

namespace refray::scenes {

// Sets SweepRow::onFront (per knob, the defaults row taking part in every knob's front) and ::onGlobalFront (the
// rows with one sample per pixel): non-dominated in (median seconds, judged RMSE), both minimised.
void markParetoFronts(SweepReport& report);

// The row with one sample per pixel and the smallest median time whose --golden comparison with the same-sampling
// reference does not fail (PASS or WARNING); empty if none.
std::optional<size_t> cheapestPassing(const SweepReport& report);

// The rows rendered with one sample per pixel (every row but the spp knob's other values).
std::vector<size_t> oneSampleRows(const SweepReport& report);
// The rows of one knob's plot and table: the defaults row and the knob's rows, ordered by the knob's value.
std::vector<size_t> knobRows(const SweepReport& report, const std::string& knob);

// One line per row, header first; see docs/accuracy-vs-time.md for the columns.
std::string sweepCsv(const SweepReport& report);
// The human report: settings, golden settings, where the defaults sit, one table and plot per knob.
std::string sweepMarkdown(const SweepReport& report);
// plots/<knob>.png per knob and plots/all.png (RMSE against median time, log-log, front dashed, defaults ringed).
// Returns the paths relative to `dir`.
std::vector<std::filesystem::path> writeSweepPlots(const std::filesystem::path& dir, const SweepReport& report);

}  // namespace refray::scenes
