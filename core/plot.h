// Scatter/line plots rendered into an Image (for `refray sweep`: error-vs-time plots with a Pareto front
// and the current default highlighted). Text uses core/draw.h; without a font the plot is drawn without text.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/image.h"

namespace refray::plot {

enum class Marker { Circle, Square, Diamond, Cross };

struct Point {
    double x = 0.0, y = 0.0;
    std::string label;  // drawn next to the marker when the series sets labelPoints
};

struct Series {
    std::string name;  // legend entry; an empty name has none
    std::vector<Point> points;
    vec4 colour = vec4(0.0f);  // alpha 0 (the default): seriesColour(index of the series)
    bool connect = true;       // a polyline through the points in the given order
    Marker marker = Marker::Circle;
    bool labelPoints = false;
};

// A point drawn with a thick gold ring edged in black and a text callout ("current default").
struct Highlight {
    double x = 0.0, y = 0.0;
    std::string text;
};

struct PlotSpec {
    std::string title, xLabel, yLabel;
    bool logX = false, logY = false;
    std::vector<Series> series;
    std::vector<Highlight> highlights;
    std::vector<Point> front;  // a Pareto front, drawn as a dashed step line over the data (any order)
    int width = 800, height = 560;
};

// One axis of a laid-out plot: the data range shown and its mapping to pixel coordinates.
struct Axis {
    double lo = 0.0, hi = 1.0;  // data range shown (both > 0 on a log axis)
    bool log = false;
    double pixelLo = 0.0, pixelHi = 1.0;  // continuous pixel coordinates of lo and hi (pixel i spans [i, i+1))
    std::vector<double> ticks;            // major ticks, labelled (niceTicks)
    std::vector<double> minorTicks;       // unlabelled: 2x and 5x each decade on a log axis, else none

    // Linear in the value, or in log10 of it on a log axis. Values outside [lo, hi] extrapolate.
    double toPixel(double value) const;
};

// Where renderPlot puts things. The plot box spans pixel columns [boxLeft, boxRight] and rows
// [boxTop, boxBottom]; x.lo maps to the centre of column boxLeft, y.lo to the centre of row boxBottom.
struct PlotLayout {
    Axis x, y;
    int boxLeft = 0, boxTop = 0, boxRight = 0, boxBottom = 0;
    bool hasData = false;  // false: nothing drawable, the plot says "no data"
};

// Ranges: the finite (and, on a log axis, positive) coordinates of all series points, highlights and front
// points, padded by 5% (of the log range on a log axis). A single value gets a range around it; no values
// give [0, 1] (linear) or [1, 10] (log). Throws refray::Error when width or height is outside [100, 8192].
PlotLayout layoutPlot(const PlotSpec& spec);

// White background, grid, series lines, the front, markers, point labels, highlights, axes box, ticks and
// labels, title and a legend in the corner of the box that covers the fewest points (none where it would
// not fit, as on a tiny plot). Points with a NaN or infinite coordinate, or a non-positive one on a log
// axis, are skipped (they break a series' line).
// Throws refray::Error when width or height is outside [100, 8192].
Image renderPlot(const PlotSpec& spec);

// Major tick values within [lo, hi], ascending. Linear: multiples of a 1-2-5 step giving about 5 intervals
// ((0, 1) -> 0, 0.2, ..., 1). Log: the powers of ten inside (every k-th decade when there are many);
// when fewer than two fit, 1-2-5 values per decade, then linear ticks. Empty when lo or hi is not finite,
// lo > hi, or (log) lo <= 0.
std::vector<double> niceTicks(double lo, double hi, bool log);

// Indices of the points not dominated when minimising both x and y (a point dominates another when it is <=
// in both and < in one), sorted by x ascending. NaN points are never on the front; of duplicates the first
// is kept.
std::vector<size_t> paretoFront(const std::vector<Point>& points);

// The i-th colour of the Okabe–Ito colour-blind-friendly palette (sRGB values as written to PNG), cycling;
// ordered for legibility on white (the yellow comes last).
vec4 seriesColour(size_t i);

}  // namespace refray::plot
