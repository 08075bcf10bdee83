#include "core/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <tuple>

#include "core/draw.h"
#include "core/error.h"

namespace refray::plot {

namespace {

const vec4 kWhite(1.0f);
const vec4 kInk(0.15f, 0.15f, 0.15f, 1.0f);
const vec4 kMuted(0.40f, 0.40f, 0.40f, 1.0f);
const vec4 kGrid(0.86f, 0.86f, 0.86f, 1.0f);
const vec4 kMinorGrid(0.94f, 0.94f, 0.94f, 1.0f);
const vec4 kGold(1.0f, 0.76f, 0.04f, 1.0f);
const vec4 kBlack(0.0f, 0.0f, 0.0f, 1.0f);

double pow10(int e) { return e >= 0 ? std::pow(10.0, e) : 1.0 / std::pow(10.0, -e); }

bool usable(double v, bool log) { return std::isfinite(v) && (!log || v > 0.0); }

// ---- Ticks, ranges and labels ----

// Multiples of a 1-2-5 step in [lo, hi]; `step` receives the step.
std::vector<double> linearTicks(double lo, double hi, double* step = nullptr) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || !std::isfinite(hi - lo) || lo > hi) return {};
    if (lo == hi) return {lo};
    const double raw = (hi - lo) / 5.0;
    const int e = int(std::floor(std::log10(raw)));
    const double m = raw / pow10(e);
    const long long unit = m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10;
    const double stepValue = double(unit) * pow10(e);
    if (step) *step = stepValue;
    if (std::max(std::abs(lo), std::abs(hi)) / stepValue > 1e15) return {lo, hi};
    // Tick k is k*unit*10^e, computed from integers so that 0.6 is the double nearest 0.6.
    std::vector<double> ticks;
    const long long k0 = std::llround(std::ceil(lo / stepValue - 1e-9)), k1 = std::llround(std::floor(hi / stepValue + 1e-9));
    for (long long k = k0; k <= k1; ++k)
        ticks.push_back(e >= 0 ? double(k * unit) * pow10(e) : double(k * unit) / pow10(-e));
    return ticks;
}

std::vector<double> ticksFor(double lo, double hi, bool log, std::vector<double>* minor) {
    if (!log) return linearTicks(lo, hi);
    if (!std::isfinite(lo) || !std::isfinite(hi) || lo <= 0.0 || lo > hi) return {};
    const auto inside = [&](double v) { return v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9); };
    const int e0 = int(std::floor(std::log10(lo))), e1 = int(std::ceil(std::log10(hi)));
    std::vector<double> decades, oneTwoFive;
    for (int e = e0; e <= e1; ++e) {
        if (inside(pow10(e))) decades.push_back(pow10(e));
        for (double m : {1.0, 2.0, 5.0})
            if (inside(m * pow10(e))) oneTwoFive.push_back(m * pow10(e));
    }
    if (decades.size() >= 3) {
        // Every stride-th decade is labelled so that at most 8 are; the others become minor ticks.
        const size_t stride = (decades.size() + 7) / 8;
        std::vector<double> major;
        for (size_t i = 0; i < decades.size(); ++i) {
            const int e = int(std::lround(std::log10(decades[i])));
            if (e % int(stride) == 0) major.push_back(decades[i]);
            else if (minor) minor->push_back(decades[i]);
            if (minor && stride == 1)
                for (double m : {2.0, 5.0})
                    if (inside(m * decades[i])) minor->push_back(m * decades[i]);
        }
        if (minor && stride == 1)
            for (double m : {2.0, 5.0})  // the partial decade below the first power of ten
                if (inside(m * decades.front() / 10.0)) minor->push_back(m * decades.front() / 10.0);
        return major;
    }
    if (oneTwoFive.size() >= 3) return oneTwoFive;
    return linearTicks(lo, hi);
}

// The padded range of one axis's values (see layoutPlot).
std::pair<double, double> axisRange(const std::vector<double>& values, bool log) {
    if (values.empty()) return log ? std::pair(1.0, 10.0) : std::pair(0.0, 1.0);
    const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
    double a = log ? std::log10(*lowest) : *lowest, b = log ? std::log10(*highest) : *highest;
    if (b - a <= 1e-9 * std::max(std::abs(a), std::abs(b))) {
        // One value (or values equal to nine digits): half a decade, or 10%, either side.
        const double pad = log ? 0.5 : (a == 0.0 ? 1.0 : 0.1 * std::abs(a));
        a -= pad;
        b += pad;
    } else {
        const double pad = 0.05 * (b - a);
        a -= pad;
        b += pad;
    }
    return log ? std::pair(std::pow(10.0, a), std::pow(10.0, b)) : std::pair(a, b);
}

// The shortest label that reads back within `tolerance`: fixed notation for moderate magnitudes,
// else "1.5e-7".
std::string formatTick(double v, double tolerance) {
    if (v == 0.0) return "0";
    char text[64];
    int digits = 1;
    for (; digits < 15; ++digits) {
        std::snprintf(text, sizeof text, "%.*e", digits - 1, v);
        if (std::abs(std::strtod(text, nullptr) - v) <= tolerance) break;
    }
    const int exponent = int(std::floor(std::log10(std::abs(v)) + 1e-12));
    if (std::abs(v) >= 1e-4 && std::abs(v) < 1e6) {
        std::snprintf(text, sizeof text, "%.*f", std::max(0, digits - 1 - exponent), v);
        return text;
    }
    std::string s = text;  // "1.5e-07" -> "1.5e-7", "1e+06" -> "1e6"
    const size_t e = s.find('e');
    std::string power = s.substr(e + 1);
    const bool negative = power[0] == '-';
    power.erase(0, power.find_first_not_of("+-0"));
    return s.substr(0, e) + "e" + (negative ? "-" : "") + power;
}

std::vector<std::string> tickLabels(const Axis& axis) {
    const double spacing = axis.ticks.size() >= 2 ? axis.ticks[1] - axis.ticks[0] : axis.hi - axis.lo;
    std::vector<std::string> labels;
    for (double t : axis.ticks) labels.push_back(formatTick(t, axis.log ? 1e-6 * std::abs(t) : 1e-3 * spacing));
    return labels;
}

// ---- Sizes and text ----

struct Style {
    double s;  // scale relative to an 800x560 plot
    int title, label, tick, legend, note, tickLength, pad;
    float marker, lineHalfWidth;
};

Style styleFor(const PlotSpec& spec) {
    const double s = std::clamp(std::min(spec.width / 800.0, spec.height / 560.0), 0.75, 4.0);
    const auto px = [&](double v) { return int(std::lround(v * s)); };
    return {s, px(19), px(15), px(13), px(13), px(11), px(5), px(12), float(4.5 * s), float(0.9 * s)};
}

int textWidth(const std::string& text, int size) { return text.empty() ? 0 : textExtent(text, size).first; }
int capHeight(int size) { return int(std::lround(0.73 * size)); }

enum class Align { Left, Centre, Right };

// Draws `text` with its baseline at y, its left edge, centre or right edge at x.
void text(Image& image, double x, double y, const std::string& text, int size, vec4 colour, Align align) {
    const int w = textWidth(text, size);
    const double left = align == Align::Left ? x : align == Align::Centre ? x - 0.5 * w : x - w;
    drawText(image, int(std::lround(left)), int(std::lround(y)), text, size, colour);
}

// Draws `text` reading upwards, centred on (cx, cy): rendered into a transparent strip, rotated in.
void textUp(Image& image, int cx, int cy, const std::string& text, int size, vec4 colour) {
    const int w = textWidth(text, size) + 4, h = int(std::lround(1.4 * size));
    if (w <= 4) return;
    Image strip(uint32_t(w), uint32_t(h), vec4(0.0f));
    drawText(strip, 2, int(std::lround(1.05 * size)), text, size, colour);
    const int x0 = cx - h / 2, y0 = cy + w / 2;  // strip pixel (u, v) lands on (x0 + v, y0 - u)
    for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
            const int x = x0 + v, y = y0 - u;
            const vec4 src = strip.at(uint32_t(u), uint32_t(v));  // premultiplied by render_text's coverage
            if (src.a <= 0.0f || x < 0 || y < 0 || x >= int(image.width()) || y >= int(image.height())) continue;
            vec4& dst = image.at(uint32_t(x), uint32_t(y));
            dst = src + (1.0f - src.a) * dst;
        }
}

// Every k-th tick is labelled, k the smallest power of two that keeps neighbouring labels `gap` apart.
size_t labelStride(const Axis& axis, const std::vector<std::string>& labels, int size, int gap, bool horizontal) {
    size_t every = 1;
    for (; every < labels.size(); every *= 2) {
        bool crowded = false;
        for (size_t i = every; i < labels.size(); i += every) {
            const double room = std::abs(axis.toPixel(axis.ticks[i]) - axis.toPixel(axis.ticks[i - every]));
            const double need = horizontal ? 0.5 * (textWidth(labels[i], size) + textWidth(labels[i - every], size)) : capHeight(size);
            crowded |= room < need + gap;
        }
        if (!crowded) break;
    }
    return every;
}

// ---- Antialiased shapes ----

struct Clip {
    int x0, y0, x1, y1;  // inclusive pixel bounds
};

Clip imageClip(const Image& image) { return {0, 0, int(image.width()) - 1, int(image.height()) - 1}; }

int clampToInt(double v, int lo, int hi) { return int(std::clamp(std::floor(v), double(lo), double(hi))); }

void blendPixel(Image& image, int x, int y, vec4 colour, float coverage) {
    const float a = std::clamp(coverage, 0.0f, 1.0f) * colour.a;
    if (a <= 0.0f) return;
    vec4& p = image.at(uint32_t(x), uint32_t(y));
    p = vec4(glm::mix(vec3(p), vec3(colour), a), a + p.a * (1.0f - a));
}

void blendRect(Image& image, int x0, int y0, int x1, int y1, vec4 colour) {
    const Clip c = imageClip(image);
    for (int y = std::max(y0, c.y0); y <= std::min(y1, c.y1); ++y)
        for (int x = std::max(x0, c.x0); x <= std::min(x1, c.x1); ++x) blendPixel(image, x, y, colour, 1.0f);
}

void outlineRect(Image& image, int x0, int y0, int x1, int y1, vec4 colour) {
    blendRect(image, x0, y0, x1, y0, colour);
    blendRect(image, x0, y1, x1, y1, colour);
    blendRect(image, x0, y0, x0, y1, colour);
    blendRect(image, x1, y0, x1, y1, colour);
}

// Fills the shape with signed distance `sdf` (pixels, negative inside) inside [lo, hi]: a pixel's coverage
// is clamp(0.5 - distance at its centre), a box filter about one pixel wide across the edge.
template <class Sdf>
void fillShape(Image& image, const Clip& clip, vec2 lo, vec2 hi, vec4 colour, Sdf sdf) {
    const int x0 = clampToInt(lo.x - 1.0, clip.x0, clip.x1 + 1), x1 = clampToInt(hi.x + 1.0, clip.x0 - 1, clip.x1);
    const int y0 = clampToInt(lo.y - 1.0, clip.y0, clip.y1 + 1), y1 = clampToInt(hi.y + 1.0, clip.y0 - 1, clip.y1);
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) blendPixel(image, x, y, colour, 0.5f - sdf(vec2(x + 0.5f, y + 0.5f)));
}

float boxDistance(vec2 q, vec2 half) {  // q in the positive quadrant
    const vec2 e = q - half;
    return glm::length(glm::max(e, vec2(0.0f))) + std::min(std::max(e.x, e.y), 0.0f);
}

float markerDistance(Marker marker, vec2 p, float r) {
    const vec2 d = glm::abs(p);
    switch (marker) {
        case Marker::Circle: return glm::length(p) - r;
        case Marker::Square: return boxDistance(d, vec2(0.85f * r));
        case Marker::Diamond: return (d.x + d.y - 1.3f * r) * 0.70710678f;
        case Marker::Cross: {
            const vec2 q = glm::abs(vec2(p.x + p.y, p.x - p.y)) * 0.70710678f;  // an X is a plus turned 45 degrees
            const float arm = 1.2f * r, half = std::max(0.8f, 0.3f * r);
            return std::min(boxDistance(q, vec2(arm, half)), boxDistance(q, vec2(half, arm)));
        }
    }
    return glm::length(p) - r;
}

// A marker with a thin white halo so that it stands out on lines and other markers.
void drawMarker(Image& image, const Clip& clip, Marker marker, vec2 c, float r, vec4 colour, float halo) {
    const vec2 extent(1.5f * r + halo);
    fillShape(image, clip, c - extent, c + extent, kWhite, [&](vec2 p) { return markerDistance(marker, p - c, r) - halo; });
    fillShape(image, clip, c - extent, c + extent, colour, [&](vec2 p) { return markerDistance(marker, p - c, r); });
}

void drawRing(Image& image, vec2 c, float radius, float halfWidth, vec4 colour) {
    const vec2 extent(radius + halfWidth);
    fillShape(image, imageClip(image), c - extent, c + extent, colour,
              [&](vec2 p) { return std::abs(glm::length(p - c) - radius) - halfWidth; });
}

float segmentDistance(vec2 p, vec2 a, vec2 b) {
    const vec2 ab = b - a;
    const float len2 = glm::dot(ab, ab);
    const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    return glm::length(p - (a + t * ab));
}

// Coverage of one stroked path, composited in one go so that the joints of a polyline do not darken.
// A segment is a capsule of the given half width; coverage is the distance-based box filter of fillShape,
// combined with max across segments.
class Layer {
public:
    Layer(const Image& image, Clip clip) : width_(int(image.width())), clip_(clip), coverage_(image.pixels().size(), 0.0f) {}

    void stroke(vec2 a, vec2 b, float halfWidth) {
        const float reach = halfWidth + 1.0f;
        const int y0 = clampToInt(std::min(a.y, b.y) - reach, clip_.y0, clip_.y1 + 1);
        const int y1 = clampToInt(std::max(a.y, b.y) + reach, clip_.y0 - 1, clip_.y1);
        for (int y = y0; y <= y1; ++y) {
            // Only the part of the segment within `reach` of this row can cover it.
            const float yc = y + 0.5f;
            float t0 = 0.0f, t1 = 1.0f;
            if (a.y != b.y) {
                const float ta = (yc - reach - a.y) / (b.y - a.y), tb = (yc + reach - a.y) / (b.y - a.y);
                t0 = std::max(0.0f, std::min(ta, tb));
                t1 = std::min(1.0f, std::max(ta, tb));
                if (t0 > t1) continue;
            } else if (std::abs(a.y - yc) > reach) {
                continue;
            }
            const float xa = a.x + t0 * (b.x - a.x), xb = a.x + t1 * (b.x - a.x);
            const int x0 = clampToInt(std::min(xa, xb) - reach, clip_.x0, clip_.x1 + 1);
            const int x1 = clampToInt(std::max(xa, xb) + reach, clip_.x0 - 1, clip_.x1);
            for (int x = x0; x <= x1; ++x) {
                const float c = halfWidth + 0.5f - segmentDistance(vec2(x + 0.5f, yc), a, b);
                if (c <= 0.0f) continue;
                float& cell = coverage_[size_t(y) * size_t(width_) + size_t(x)];
                cell = std::max(cell, std::min(c, 1.0f));
            }
        }
    }

    // Dashes of `on` pixels every `on + off` pixels along the whole path.
    void dashed(const std::vector<vec2>& path, float halfWidth, float on, float off) {
        const float period = on + off;
        float start = 0.0f;  // path length before the segment
        for (size_t i = 1; i < path.size(); ++i) {
            const float length = glm::length(path[i] - path[i - 1]);
            if (length <= 0.0f) continue;
            const vec2 dir = (path[i] - path[i - 1]) / length;
            for (float k = std::floor(start / period); k * period < start + length; k += 1.0f) {
                const float s0 = std::max(k * period, start) - start, s1 = std::min(k * period + on, start + length) - start;
                if (s1 > s0) stroke(path[i - 1] + s0 * dir, path[i - 1] + s1 * dir, halfWidth);
            }
            start += length;
        }
    }

    void composite(Image& image, vec4 colour) {
        for (size_t i = 0; i < coverage_.size(); ++i)
            if (coverage_[i] > 0.0f) {
                blendPixel(image, int(i % size_t(width_)), int(i / size_t(width_)), colour, coverage_[i]);
                coverage_[i] = 0.0f;
            }
    }

private:
    int width_;
    Clip clip_;
    std::vector<float> coverage_;
};

// ---- Legend ----

struct LegendEntry {
    std::string name;
    vec4 colour;
    Marker marker;
    bool line, dashed, markers;
};

struct Rect {
    int x0, y0, x1, y1;  // inclusive
    bool contains(vec2 p, float margin) const {
        return p.x >= x0 - margin && p.x <= x1 + 1 + margin && p.y >= y0 - margin && p.y <= y1 + 1 + margin;
    }
};

vec4 colourOf(const Series& series, size_t index) { return series.colour.a > 0.0f ? series.colour : seriesColour(index); }

}  // namespace

double Axis::toPixel(double value) const {
    const double t = log ? (std::log10(value) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (value - lo) / (hi - lo);
    return pixelLo + t * (pixelHi - pixelLo);
}

std::vector<double> niceTicks(double lo, double hi, bool log) { return ticksFor(lo, hi, log, nullptr); }

std::vector<size_t> paretoFront(const std::vector<Point>& points) {
    std::vector<size_t> order;
    for (size_t i = 0; i < points.size(); ++i)
        if (!std::isnan(points[i].x) && !std::isnan(points[i].y)) order.push_back(i);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (points[a].x != points[b].x) return points[a].x < points[b].x;
        if (points[a].y != points[b].y) return points[a].y < points[b].y;
        return a < b;
    });
    // Sweeping by x, a point is on the front exactly when its y is below every y seen so far.
    std::vector<size_t> front;
    for (size_t i : order)
        if (front.empty() || points[i].y < points[front.back()].y) front.push_back(i);
    return front;
}

vec4 seriesColour(size_t i) {
    static const vec4 kPalette[] = {
        {0.000f, 0.447f, 0.698f, 1.0f},  // blue
        {0.835f, 0.369f, 0.000f, 1.0f},  // vermillion
        {0.000f, 0.620f, 0.451f, 1.0f},  // bluish green
        {0.800f, 0.475f, 0.655f, 1.0f},  // reddish purple
        {0.902f, 0.624f, 0.000f, 1.0f},  // orange
        {0.337f, 0.706f, 0.914f, 1.0f},  // sky blue
        {0.000f, 0.000f, 0.000f, 1.0f},  // black
        {0.941f, 0.894f, 0.259f, 1.0f},  // yellow
    };
    return kPalette[i % std::size(kPalette)];
}

PlotLayout layoutPlot(const PlotSpec& spec) {
    REFRAY_CHECK(spec.width >= 100 && spec.width <= 8192 && spec.height >= 100 && spec.height <= 8192,
                 "plot size " << spec.width << "x" << spec.height << " is outside 100..8192 pixels per side");
    const Style st = styleFor(spec);

    std::vector<double> xs, ys;
    const auto add = [&](double x, double y) {
        if (!usable(x, spec.logX) || !usable(y, spec.logY)) return;
        xs.push_back(x);
        ys.push_back(y);
    };
    for (const Series& series : spec.series)
        for (const Point& p : series.points) add(p.x, p.y);
    for (const Highlight& h : spec.highlights) add(h.x, h.y);
    for (const Point& p : spec.front) add(p.x, p.y);

    PlotLayout layout;
    layout.hasData = !xs.empty();
    std::tie(layout.x.lo, layout.x.hi) = axisRange(xs, spec.logX);
    std::tie(layout.y.lo, layout.y.hi) = axisRange(ys, spec.logY);
    layout.x.log = spec.logX;
    layout.y.log = spec.logY;
    layout.x.ticks = ticksFor(layout.x.lo, layout.x.hi, spec.logX, &layout.x.minorTicks);
    layout.y.ticks = ticksFor(layout.y.lo, layout.y.hi, spec.logY, &layout.y.minorTicks);

    // Margins: room for the title, tick labels and axis labels.
    int yTickWidth = 0;
    for (const std::string& label : tickLabels(layout.y)) yTickWidth = std::max(yTickWidth, textWidth(label, st.tick));
    const std::vector<std::string> xLabels = tickLabels(layout.x);
    const int lastXTickHalf = xLabels.empty() ? 0 : textWidth(xLabels.back(), st.tick) / 2;
    const int gap = int(std::lround(6 * st.s));
    const int left = st.pad + (spec.yLabel.empty() ? 0 : int(1.4 * st.label) + gap) + yTickWidth + st.tickLength + gap;
    const int top = spec.title.empty() ? 2 * st.pad : int(2.4 * st.title);
    const int bottom = st.tickLength + gap + capHeight(st.tick) + (spec.xLabel.empty() ? 0 : gap + int(1.5 * st.label)) + st.pad;
    const int right = std::max(2 * st.pad, lastXTickHalf + gap);
    layout.boxLeft = std::min(left, spec.width / 2 - 10);
    layout.boxTop = std::min(top, spec.height / 2 - 10);
    layout.boxRight = std::max(spec.width - 1 - right, spec.width / 2 + 10);
    layout.boxBottom = std::max(spec.height - 1 - bottom, spec.height / 2 + 10);
    layout.x.pixelLo = layout.boxLeft + 0.5;
    layout.x.pixelHi = layout.boxRight + 0.5;
    layout.y.pixelLo = layout.boxBottom + 0.5;
    layout.y.pixelHi = layout.boxTop + 0.5;
    return layout;
}

Image renderPlot(const PlotSpec& spec) {
    const PlotLayout layout = layoutPlot(spec);
    const Style st = styleFor(spec);
    Image image(uint32_t(spec.width), uint32_t(spec.height), kWhite);
    const Clip box{layout.boxLeft, layout.boxTop, layout.boxRight, layout.boxBottom};
    const auto drawable = [&](double x, double y) { return usable(x, spec.logX) && usable(y, spec.logY); };
    const auto toPixel = [&](double x, double y) { return vec2(float(layout.x.toPixel(x)), float(layout.y.toPixel(y))); };
    const auto column = [&](double v) { return int(std::floor(layout.x.toPixel(v))); };
    const auto row = [&](double v) { return int(std::floor(layout.y.toPixel(v))); };

    // Grid.
    for (double v : layout.x.minorTicks) blendRect(image, column(v), box.y0, column(v), box.y1, kMinorGrid);
    for (double v : layout.y.minorTicks) blendRect(image, box.x0, row(v), box.x1, row(v), kMinorGrid);
    for (double v : layout.x.ticks) blendRect(image, column(v), box.y0, column(v), box.y1, kGrid);
    for (double v : layout.y.ticks) blendRect(image, box.x0, row(v), box.x1, row(v), kGrid);

    // Series lines, broken at skipped points; the samples also steer the legend away from them.
    std::vector<vec2> markerSpots, lineSpots, highlightSpots;
    Layer layer(image, box);
    for (size_t i = 0; i < spec.series.size(); ++i) {
        const Series& series = spec.series[i];
        std::optional<vec2> previous;
        for (const Point& p : series.points) {
            if (!drawable(p.x, p.y)) {
                previous.reset();
                continue;
            }
            const vec2 here = toPixel(p.x, p.y);
            markerSpots.push_back(here);
            if (series.connect && previous) {
                layer.stroke(*previous, here, st.lineHalfWidth);
                const float steps = std::ceil(glm::length(here - *previous) / 6.0f);
                for (float k = 1.0f; k < steps; k += 1.0f) lineSpots.push_back(glm::mix(*previous, here, k / steps));
            }
            previous = here;
        }
        layer.composite(image, colourOf(series, i));
    }

    // The Pareto front: a staircase through its points sorted by x (the boundary of the dominated region).
    std::vector<Point> front;
    for (const Point& p : spec.front)
        if (drawable(p.x, p.y)) front.push_back(p);
    std::sort(front.begin(), front.end(), [](const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (!front.empty()) {
        std::vector<vec2> path{toPixel(front[0].x, front[0].y)};
        for (size_t i = 1; i < front.size(); ++i) {
            path.push_back(toPixel(front[i].x, front[i - 1].y));
            path.push_back(toPixel(front[i].x, front[i].y));
        }
        for (const vec2& p : path) lineSpots.push_back(p);
        layer.dashed(path, float(0.85 * st.s), float(7 * st.s), float(4 * st.s));
        layer.composite(image, vec4(vec3(kInk), 0.85f));
    }

    // Markers over all lines.
    const float halo = float(1.2 * st.s);
    for (size_t i = 0; i < spec.series.size(); ++i)
        for (const Point& p : spec.series[i].points)
            if (drawable(p.x, p.y))
                drawMarker(image, box, spec.series[i].marker, toPixel(p.x, p.y), st.marker, colourOf(spec.series[i], i), halo);

    // Point labels up and to the right, or right of a highlight's ring (its callout goes above), then
    // highlights with their callouts.
    const float ringRadius = float(10 * st.s);
    for (size_t i = 0; i < spec.series.size(); ++i) {
        if (!spec.series[i].labelPoints) continue;
        const vec4 colour = vec4(0.7f * vec3(colourOf(spec.series[i], i)), 1.0f);
        for (const Point& p : spec.series[i].points) {
            if (!drawable(p.x, p.y) || p.label.empty()) continue;
            const vec2 c = toPixel(p.x, p.y);
            const bool ringed = std::any_of(spec.highlights.begin(), spec.highlights.end(), [&](const Highlight& h) {
                return drawable(h.x, h.y) && glm::length(toPixel(h.x, h.y) - c) < ringRadius;
            });
            if (ringed) text(image, c.x + ringRadius + 5 * st.s, c.y + 0.5 * capHeight(st.note), p.label, st.note, colour, Align::Left);
            else text(image, c.x + st.marker + 3 * st.s, c.y - st.marker - 1 * st.s, p.label, st.note, colour, Align::Left);
        }
    }
    for (const Highlight& h : spec.highlights) {
        if (!drawable(h.x, h.y)) continue;
        const vec2 c = toPixel(h.x, h.y);
        highlightSpots.push_back(c);
        drawRing(image, c, ringRadius, float(2.6 * st.s), kBlack);
        drawRing(image, c, ringRadius, float(1.5 * st.s), kGold);
        if (h.text.empty()) continue;
        // Callout up and to the right of the ring, flipped where it would leave the plot box.
        const int w = textWidth(h.text, st.legend), pad = int(std::lround(4 * st.s));
        const int boxH = capHeight(st.legend) + 2 * pad;
        const float offset = ringRadius + float(8 * st.s);
        const bool leftSide = c.x + offset + w + 2 * pad > box.x1 - 2;
        const bool below = c.y - offset - boxH < box.y0 + 2;
        const int bx0 = int(leftSide ? c.x - offset - w - 2 * pad : c.x + offset);
        const int by0 = int(below ? c.y + offset : c.y - offset - boxH);
        const vec2 corner(leftSide ? bx0 + w + 2 * pad : bx0, below ? by0 : by0 + boxH);
        const vec2 dir = glm::normalize(corner - c);
        Layer leader(image, imageClip(image));
        leader.stroke(c + dir * (ringRadius + float(2.6 * st.s)), corner, float(0.6 * st.s));
        leader.composite(image, kBlack);
        blendRect(image, bx0, by0, bx0 + w + 2 * pad, by0 + boxH, vec4(1.0f, 0.97f, 0.85f, 0.95f));
        outlineRect(image, bx0, by0, bx0 + w + 2 * pad, by0 + boxH, kBlack);
        text(image, bx0 + pad, by0 + pad + capHeight(st.legend), h.text, st.legend, kBlack, Align::Left);
        highlightSpots.push_back(vec2(bx0 + 0.5f * w, by0 + 0.5f * boxH));
    }

    // Axes box, ticks and tick labels; x labels are thinned out while neighbours would touch.
    outlineRect(image, box.x0, box.y0, box.x1, box.y1, kInk);
    const int gap = int(std::lround(6 * st.s));
    const std::vector<std::string> xLabels = tickLabels(layout.x), yLabels = tickLabels(layout.y);
    const size_t xEvery = labelStride(layout.x, xLabels, st.tick, gap, true);
    const size_t yEvery = labelStride(layout.y, yLabels, st.tick, gap, false);
    for (size_t i = 0; i < layout.x.ticks.size(); ++i) {
        const int x = column(layout.x.ticks[i]);
        blendRect(image, x, box.y1 + 1, x, box.y1 + st.tickLength, kInk);
        if (i % xEvery == 0)
            text(image, x + 0.5, box.y1 + st.tickLength + gap + capHeight(st.tick), xLabels[i], st.tick, kInk, Align::Centre);
    }
    for (double v : layout.x.minorTicks) blendRect(image, column(v), box.y1 + 1, column(v), box.y1 + st.tickLength / 2, kInk);
    for (size_t i = 0; i < layout.y.ticks.size(); ++i) {
        const int y = row(layout.y.ticks[i]);
        blendRect(image, box.x0 - st.tickLength, y, box.x0 - 1, y, kInk);
        if (i % yEvery == 0)
            text(image, box.x0 - st.tickLength - gap, y + 0.5 + 0.5 * capHeight(st.tick), yLabels[i], st.tick, kInk, Align::Right);
    }
    for (double v : layout.y.minorTicks) blendRect(image, box.x0 - st.tickLength / 2, row(v), box.x0 - 1, row(v), kInk);
    if (!layout.hasData)
        text(image, 0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1) + 0.5 * capHeight(st.label), "no data", st.label, kMuted,
             Align::Centre);

    // Title and axis labels.
    if (!spec.title.empty())
        text(image, 0.5 * (box.x0 + box.x1), 0.5 * box.y0 + 0.5 * capHeight(st.title), spec.title, st.title, kBlack, Align::Centre);
    if (!spec.xLabel.empty())
        text(image, 0.5 * (box.x0 + box.x1), spec.height - 1 - st.pad, spec.xLabel, st.label, kInk, Align::Centre);
    if (!spec.yLabel.empty())
        textUp(image, st.pad + int(0.7 * st.label), (box.y0 + box.y1) / 2, spec.yLabel, st.label, kInk);

    // Legend, in the corner of the box that covers the fewest markers, highlights and line samples; none
    // where it would not fit.
    std::vector<LegendEntry> entries;
    for (size_t i = 0; i < spec.series.size(); ++i)
        if (!spec.series[i].name.empty())
            entries.push_back({spec.series[i].name, colourOf(spec.series[i], i), spec.series[i].marker, spec.series[i].connect,
                               false, true});
    if (!front.empty()) entries.push_back({"Pareto front", vec4(vec3(kInk), 0.85f), Marker::Circle, true, true, false});
    if (entries.empty()) return image;
    const int rowHeight = int(std::lround(1.55 * st.legend)), swatch = int(std::lround(28 * st.s)), pad = int(std::lround(8 * st.s));
    int nameWidth = 0;
    for (const LegendEntry& e : entries) nameWidth = std::max(nameWidth, textWidth(e.name, st.legend));
    const int w = pad + swatch + gap + nameWidth + pad, h = 2 * pad + rowHeight * int(entries.size()) - (rowHeight - capHeight(st.legend)) + 2;
    const int inset = int(std::lround(8 * st.s));
    if (w + 2 * inset > box.x1 - box.x0 || h + 2 * inset > box.y1 - box.y0) return image;  // a legend would hide the plot
    const Rect candidates[] = {{box.x1 - inset - w, box.y0 + inset, box.x1 - inset, box.y0 + inset + h},
                               {box.x0 + inset, box.y0 + inset, box.x0 + inset + w, box.y0 + inset + h},
                               {box.x1 - inset - w, box.y1 - inset - h, box.x1 - inset, box.y1 - inset},
                               {box.x0 + inset, box.y1 - inset - h, box.x0 + inset + w, box.y1 - inset}};
    Rect best = candidates[0];
    double bestScore = 1e300;
    for (const Rect& r : candidates) {
        double score = 0.0;
        for (const vec2& p : markerSpots) score += r.contains(p, st.marker) ? 1.0 : 0.0;
        for (const vec2& p : lineSpots) score += r.contains(p, st.lineHalfWidth) ? 0.2 : 0.0;
        for (const vec2& p : highlightSpots) score += r.contains(p, ringRadius) ? 10.0 : 0.0;
        if (score < bestScore) {
            bestScore = score;
            best = r;
        }
    }
    blendRect(image, best.x0, best.y0, best.x1, best.y1, vec4(1.0f, 1.0f, 1.0f, 0.9f));
    outlineRect(image, best.x0, best.y0, best.x1, best.y1, vec4(0.6f, 0.6f, 0.6f, 1.0f));
    Layer swatches(image, imageClip(image));
    for (size_t i = 0; i < entries.size(); ++i) {
        const LegendEntry& e = entries[i];
        const float baseline = float(best.y0 + pad + capHeight(st.legend) + int(i) * rowHeight);
        const vec2 a(best.x0 + pad, baseline - 0.5f * capHeight(st.legend)), b = a + vec2(swatch, 0.0f);
        if (e.dashed) swatches.dashed({a, b}, float(0.85 * st.s), float(7 * st.s), float(4 * st.s));
        else if (e.line) swatches.stroke(a, b, st.lineHalfWidth);
        swatches.composite(image, e.colour);
        if (e.markers) drawMarker(image, imageClip(image), e.marker, 0.5f * (a + b), st.marker, e.colour, halo);
        text(image, b.x + gap, baseline, e.name, st.legend, kInk, Align::Left);
    }
    return image;
}

}  // namespace refray::plot
