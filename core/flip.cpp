#include "core/flip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "core/error.h"

namespace refray {

namespace {

constexpr double kPi = 3.14159265358979323846;

// --- The paper's constants -------------------------------------------------------

// Contrast sensitivity of each opponent channel as a sum of two Gaussians in the
// spatial domain: a1 sqrt(pi/b1) exp(-pi^2 x^2/b1) + a2 sqrt(pi/b2) exp(-pi^2 x^2/b2),
// x in degrees.
struct CsfParameters {
    double a1, b1, a2, b2;
};
constexpr CsfParameters kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
constexpr CsfParameters kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
constexpr CsfParameters kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};
constexpr double kLargestCsfScale = 0.04;  // the widest b: it sets the filter radius

constexpr double kColourExponent = 0.7;         // q_c
constexpr double kFeatureExponent = 0.5;        // q_f
constexpr double kColourBreakpoint = 0.4;       // p_c
constexpr double kColourBreakpointValue = 0.95;  // p_t
constexpr double kFeatureWidthDegrees = 0.082;  // w: peak-to-trough width of the edge detector

// --- Colour spaces ---------------------------------------------------------------

using Matrix3 = std::array<std::array<double, 3>, 3>;

// Linear sRGB (ITU-R BT.709 primaries, D65 white) to CIE XYZ.
constexpr Matrix3 kLinearRGBToXYZ{{{0.4124564, 0.3575761, 0.1804375},
                                   {0.2126729, 0.7151522, 0.0721750},
                                   {0.0193339, 0.1191920, 0.9503041}}};

Matrix3 inverse(const Matrix3& m) {
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    Matrix3 r{};
    r[0] = {c00 / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det};
    r[1] = {c01 / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det};
    r[2] = {c02 / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det};
    return r;
}

dvec3 multiply(const Matrix3& m, dvec3 v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

// The matrices and the white point in the precision the per-pixel work uses. The white
// is the XYZ of RGB (1, 1, 1), so white has a* = b* = 0 exactly.
struct ColourSpace {
    std::array<std::array<float, 3>, 3> toXYZ{}, toRGB{};
    vec3 white{};

    ColourSpace() {
        const Matrix3 back = inverse(kLinearRGBToXYZ);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                toXYZ[i][j] = float(kLinearRGBToXYZ[i][j]);
                toRGB[i][j] = float(back[i][j]);
            }
        white = vec3(multiply(kLinearRGBToXYZ, dvec3(1.0)));
    }

    static vec3 apply(const std::array<std::array<float, 3>, 3>& m, vec3 v) {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
};

const ColourSpace& colourSpace() {
    static const ColourSpace space;
    return space;
}

float displayToLinear(float c) {
    c = std::isnan(c) ? 0.0f : std::clamp(c, 0.0f, 1.0f);
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// YyCxCz: the linearised CIELAB the paper filters in (no cube root, so filtering is linear).
vec3 linearRGBToYCxCz(vec3 rgb) {
    const ColourSpace& cs = colourSpace();
    const vec3 n = ColourSpace::apply(cs.toXYZ, rgb) / cs.white;
    return {116.0f * n.y - 16.0f, 500.0f * (n.x - n.y), 200.0f * (n.y - n.z)};
}

vec3 yCxCzToLinearRGB(vec3 ycc) {
    const ColourSpace& cs = colourSpace();
    const float ny = (ycc.x + 16.0f) / 116.0f;
    const vec3 n(ycc.y / 500.0f + ny, ny, ny - ycc.z / 200.0f);
    return ColourSpace::apply(cs.toRGB, n * cs.white);
}

template <typename T>
T labCurve(T t) {
    constexpr T delta = T(6) / T(29);
    return t > delta * delta * delta ? std::cbrt(t) : t / (T(3) * delta * delta) + T(4) / T(29);
}

// CIELAB with the Hunt adjustment (a* and b* scaled by 0.01 L*: colours fade in the dark).
// Per pixel in float; in double for the constant cmax.
template <typename T>
glm::vec<3, T> linearRGBToHuntLab(glm::vec<3, T> rgb) {
    const ColourSpace& cs = colourSpace();
    glm::vec<3, T> xyz;
    if constexpr (std::is_same_v<T, float>) xyz = ColourSpace::apply(cs.toXYZ, rgb) / cs.white;
    else xyz = multiply(kLinearRGBToXYZ, rgb) / dvec3(cs.white);
    const T fx = labCurve(xyz.x), fy = labCurve(xyz.y), fz = labCurve(xyz.z);
    const T L = T(116) * fy - T(16);
    return {L, T(0.01) * L * T(500) * (fx - fy), T(0.01) * L * T(200) * (fy - fz)};
}

template <typename T>
T hyab(glm::vec<3, T> a, glm::vec<3, T> b) {
    const glm::vec<3, T> d = a - b;
    return std::abs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

// The largest colour error: HyAB between Hunt-adjusted green and blue, raised to q_c.
double maxColourError() {
    static const double value =
        std::pow(hyab(linearRGBToHuntLab(dvec3(0.0, 1.0, 0.0)), linearRGBToHuntLab(dvec3(0.0, 0.0, 1.0))), kColourExponent);
    return value;
}

// --- Separable filters -----------------------------------------------------------

struct Plane {
    uint32_t width = 0, height = 0;
    std::vector<float> values;

    Plane() = default;
    Plane(uint32_t w, uint32_t h) : width(w), height(h), values(size_t(w) * h, 0.0f) {}
    float* row(uint32_t y) { return values.data() + size_t(y) * width; }
    const float* row(uint32_t y) const { return values.data() + size_t(y) * width; }
};

using Kernel = std::vector<float>;  // 2r + 1 taps, centre at r

// out(x, y) = sum_i kernel[i] in(x + i - r, y), the border repeated.
void filterRows(const Plane& in, const Kernel& kernel, Plane& out) {
    const int r = int(kernel.size() / 2);
    const int w = int(in.width);
    std::vector<float> padded(size_t(w + 2 * r));
    for (uint32_t y = 0; y < in.height; ++y) {
        const float* src = in.row(y);
        for (int x = 0; x < w + 2 * r; ++x) padded[size_t(x)] = src[std::clamp(x - r, 0, w - 1)];
        float* dst = out.row(y);
        std::fill(dst, dst + w, 0.0f);
        for (size_t i = 0; i < kernel.size(); ++i) {
            const float k = kernel[i];
            const float* p = padded.data() + i;
            for (int x = 0; x < w; ++x) dst[x] += k * p[x];
        }
    }
}

// out(x, y) (+)= sum_i kernel[i] in(x, y + i - r), the border repeated.
void filterColumns(const Plane& in, const Kernel& kernel, Plane& out, bool accumulate) {
    const int r = int(kernel.size() / 2);
    const int h = int(in.height);
    const uint32_t w = in.width;
    for (int y = 0; y < h; ++y) {
        float* dst = out.row(uint32_t(y));
        if (!accumulate) std::fill(dst, dst + w, 0.0f);
        for (size_t i = 0; i < kernel.size(); ++i) {
            const float k = kernel[i];
            const float* src = in.row(uint32_t(std::clamp(y + int(i) - r, 0, h - 1)));
            for (uint32_t x = 0; x < w; ++x) dst[x] += k * src[x];
        }
    }
}

// One term w * (g(x) g(y)) of a separable sum; g sums to 1.
struct SeparableTerm {
    Kernel kernel;
    float weight;
};

// The CSF of one channel as normalised separable terms. The paper normalises the whole
// 2D kernel to sum 1; with S_i the 1D sum of term i, term i's share of that sum is
// c_i S_i^2 / sum_j c_j S_j^2 (c_i = a_i sqrt(pi / b_i)).
std::vector<SeparableTerm> csfFilter(const CsfParameters& p, int radius, double pixelsPerDegree) {
    const double delta = 1.0 / pixelsPerDegree;  // degrees per pixel
    std::vector<SeparableTerm> terms;
    std::vector<double> shares;
    for (const auto& [a, b] : {std::pair{p.a1, p.b1}, std::pair{p.a2, p.b2}}) {
        if (a == 0.0) continue;
        std::vector<double> g(size_t(2 * radius + 1));
        double sum = 0.0;
        for (int x = -radius; x <= radius; ++x) {
            const double d = x * delta;
            g[size_t(x + radius)] = std::exp(-kPi * kPi * d * d / b);
            sum += g[size_t(x + radius)];
        }
        Kernel kernel(g.size());
        for (size_t i = 0; i < g.size(); ++i) kernel[i] = float(g[i] / sum);
        terms.push_back({std::move(kernel), 0.0f});
        shares.push_back(a * std::sqrt(kPi / b) * sum * sum);
    }
    double total = 0.0;
    for (double s : shares) total += s;
    for (size_t i = 0; i < terms.size(); ++i) terms[i].weight = float(shares[i] / total);
    return terms;
}

// Filters `in` with the 2D kernel sum_terms w g(x) g(y).
Plane filterSeparable(const Plane& in, const std::vector<SeparableTerm>& terms) {
    Plane out(in.width, in.height), rows(in.width, in.height);
    bool accumulate = false;
    for (const SeparableTerm& term : terms) {
        filterRows(in, term.kernel, rows);
        Kernel weighted = term.kernel;
        for (float& k : weighted) k *= term.weight;
        filterColumns(rows, weighted, out, accumulate);
        accumulate = true;
    }
    return out;
}

// The feature detectors of the paper: the first (edge) and second (point) derivative of
// a Gaussian with sigma = w/2 degrees, factored as detector(x) * gaussian(y). The 2D
// kernels have their positive weights normalised to sum 1 and their negative weights to
// sum -1; because the Gaussian factor is positive that is the same normalisation applied
// to the 1D detector, with the Gaussian factor summing to 1.
struct FeatureKernels {
    Kernel gaussian, edge, point;
};

Kernel normaliseSigned(const std::vector<double>& v) {
    double positive = 0.0, negative = 0.0;
    for (double x : v) (x > 0.0 ? positive : negative) += x;
    Kernel k(v.size());
    for (size_t i = 0; i < v.size(); ++i)
        k[i] = float(v[i] > 0.0 ? v[i] / positive : (v[i] < 0.0 ? -v[i] / negative : 0.0));
    return k;
}

FeatureKernels featureKernels(double pixelsPerDegree) {
    const double sigma = 0.5 * kFeatureWidthDegrees * pixelsPerDegree;  // in pixels
    const int radius = int(std::ceil(3.0 * sigma));
    std::vector<double> g, edge, point;
    double sum = 0.0;
    for (int x = -radius; x <= radius; ++x) {
        const double value = std::exp(-double(x) * x / (2.0 * sigma * sigma));
        g.push_back(value);
        sum += value;
        edge.push_back(-x * value);
        point.push_back((double(x) * x / (sigma * sigma) - 1.0) * value);
    }
    FeatureKernels k;
    for (double value : g) k.gaussian.push_back(float(value / sum));
    k.edge = normaliseSigned(edge);
    k.point = normaliseSigned(point);
    return k;
}

// --- Per-image preparation -------------------------------------------------------

// What the error needs from one image: its filtered Hunt-adjusted L*a*b* and the
// magnitudes of its edge and point responses.
struct Prepared {
    Plane L, a, b, edges, points;
};

Prepared prepare(const Image& image, double pixelsPerDegree) {
    const uint32_t w = image.width(), h = image.height();
    Plane yy(w, h), cx(w, h), cz(w, h), luminance(w, h);
    for (size_t i = 0; i < image.pixels().size(); ++i) {
        const vec4& p = image.pixels()[i];
        const vec3 ycc = linearRGBToYCxCz({displayToLinear(p.r), displayToLinear(p.g), displayToLinear(p.b)});
        yy.values[i] = ycc.x;
        cx.values[i] = ycc.y;
        cz.values[i] = ycc.z;
        luminance.values[i] = (ycc.x + 16.0f) / 116.0f;  // Y / Y_white, for the features
    }

    // Colour: CSF filtering in YyCxCz, back to linear RGB clamped to the gamut, then Hunt L*a*b*.
    const int radius = int(std::ceil(3.0 * std::sqrt(kLargestCsfScale / (2.0 * kPi * kPi)) * pixelsPerDegree));
    Prepared out;
    out.L = filterSeparable(yy, csfFilter(kCsfAchromatic, radius, pixelsPerDegree));
    out.a = filterSeparable(cx, csfFilter(kCsfRedGreen, radius, pixelsPerDegree));
    out.b = filterSeparable(cz, csfFilter(kCsfBlueYellow, radius, pixelsPerDegree));
    for (size_t i = 0; i < out.L.values.size(); ++i) {
        const vec3 rgb = glm::clamp(yCxCzToLinearRGB({out.L.values[i], out.a.values[i], out.b.values[i]}), 0.0f, 1.0f);
        const vec3 lab = linearRGBToHuntLab(rgb);
        out.L.values[i] = lab.x;
        out.a.values[i] = lab.y;
        out.b.values[i] = lab.z;
    }

    // Features: edge and point responses of the unfiltered luminance, in x and in y.
    const FeatureKernels k = featureKernels(pixelsPerDegree);
    Plane rowsGaussian(w, h), rowsEdge(w, h), rowsPoint(w, h), x(w, h), y(w, h);
    filterRows(luminance, k.gaussian, rowsGaussian);
    filterRows(luminance, k.edge, rowsEdge);
    filterRows(luminance, k.point, rowsPoint);
    filterColumns(rowsEdge, k.gaussian, x, false);
    filterColumns(rowsGaussian, k.edge, y, false);
    out.edges = Plane(w, h);
    for (size_t i = 0; i < x.values.size(); ++i)
        out.edges.values[i] = std::sqrt(x.values[i] * x.values[i] + y.values[i] * y.values[i]);
    filterColumns(rowsPoint, k.gaussian, x, false);
    filterColumns(rowsGaussian, k.point, y, false);
    out.points = Plane(w, h);
    for (size_t i = 0; i < x.values.size(); ++i)
        out.points.values[i] = std::sqrt(x.values[i] * x.values[i] + y.values[i] * y.values[i]);
    return out;
}

// Maps the powered HyAB distance to [0, 1]: the lowest p_c of the range onto [0, p_t],
// the rest onto [p_t, 1], so small differences are spread out.
float redistributeColourError(float error, float cmax) {
    const float knee = float(kColourBreakpoint) * cmax;
    if (error < knee) return float(kColourBreakpointValue) / knee * error;
    return std::min(1.0f, float(kColourBreakpointValue) +
                              (error - knee) / (cmax - knee) * float(1.0 - kColourBreakpointValue));
}

}  // namespace

FlipMap computeFlip(const Image& reference, const Image& test, double pixelsPerDegree) {
    REFRAY_CHECK(!reference.empty() && !test.empty(), "FLIP needs two non-empty images");
    REFRAY_CHECK(reference.width() == test.width() && reference.height() == test.height(),
                 "FLIP needs images of one size, got " << reference.width() << "x" << reference.height() << " and "
                                                       << test.width() << "x" << test.height());
    REFRAY_CHECK(std::isfinite(pixelsPerDegree) && pixelsPerDegree > 0.0,
                 "FLIP's pixels per degree must be positive, got " << pixelsPerDegree);

    const Prepared r = prepare(reference, pixelsPerDegree);
    const Prepared t = prepare(test, pixelsPerDegree);
    const float cmax = float(maxColourError());

    FlipMap map;
    map.width = reference.width();
    map.height = reference.height();
    map.error.resize(reference.pixels().size());
    for (size_t i = 0; i < map.error.size(); ++i) {
        const float colour = redistributeColourError(
            std::pow(hyab(vec3(r.L.values[i], r.a.values[i], r.b.values[i]),
                          vec3(t.L.values[i], t.a.values[i], t.b.values[i])),
                     float(kColourExponent)),
            cmax);
        const float feature = std::max(std::abs(r.edges.values[i] - t.edges.values[i]),
                                       std::abs(r.points.values[i] - t.points.values[i]));
        const float featureError = std::min(1.0f, std::pow(feature * float(1.0 / std::sqrt(2.0)), float(kFeatureExponent)));
        // A colour error of 0 stays 0 even where the exponent reaches 0 (pow(0, 0) = 1).
        map.error[i] = colour > 0.0f ? std::pow(colour, 1.0f - featureError) : 0.0f;
    }
    return map;
}

FlipStats flipStatistics(const FlipMap& map, const std::vector<uint8_t>& include) {
    REFRAY_CHECK(include.empty() || include.size() == map.error.size(),
                 "FLIP statistics: the include list has " << include.size() << " entries for "
                                                          << map.error.size() << " pixels");
    std::vector<float> values;
    values.reserve(map.error.size());
    for (size_t i = 0; i < map.error.size(); ++i)
        if (include.empty() || include[i]) values.push_back(map.error[i]);
    FlipStats stats;
    stats.pixels = values.size();
    if (values.empty()) return stats;

    double sum = 0.0;
    for (float v : values) sum += v;
    stats.mean = sum / double(values.size());
    stats.max = *std::max_element(values.begin(), values.end());
    // Selections in increasing rank, each within the part the previous one left above it.
    auto from = values.begin();
    const auto quantile = [&](double p) {
        const double rank = p * double(values.size() - 1);
        const auto low = values.begin() + ptrdiff_t(std::floor(rank));
        std::nth_element(from, low, values.end());
        from = low;
        const double f = rank - std::floor(rank);
        if (f == 0.0) return double(*low);
        return double(*low) * (1.0 - f) + double(*std::min_element(low + 1, values.end())) * f;
    };
    stats.firstQuartile = quantile(0.25);
    stats.median = quantile(0.5);
    stats.thirdQuartile = quantile(0.75);
    return stats;
}

vec3 magma(float t) {
    // matplotlib's magma sampled at nine evenly spaced points, interpolated linearly.
    static constexpr std::array<std::array<uint8_t, 3>, 9> kStops{{{0x00, 0x00, 0x04},
                                                                   {0x1d, 0x11, 0x47},
                                                                   {0x51, 0x12, 0x7c},
                                                                   {0x82, 0x26, 0x81},
                                                                   {0xb6, 0x36, 0x79},
                                                                   {0xe6, 0x51, 0x64},
                                                                   {0xfb, 0x88, 0x61},
                                                                   {0xfe, 0xc2, 0x87},
                                                                   {0xfc, 0xfd, 0xbf}}};
    const float s = (std::isnan(t) ? 1.0f : std::clamp(t, 0.0f, 1.0f)) * float(kStops.size() - 1);
    const size_t i = std::min(size_t(s), kStops.size() - 2);
    const float f = s - float(i);
    vec3 out;
    for (int c = 0; c < 3; ++c) out[c] = (kStops[i][size_t(c)] * (1.0f - f) + kStops[i + 1][size_t(c)] * f) / 255.0f;
    return out;
}

Image flipHeatMap(const FlipMap& map) {
    Image image(map.width, map.height);
    for (size_t i = 0; i < map.error.size(); ++i) image.pixels()[i] = vec4(magma(map.error[i]), 1.0f);
    return image;
}

}  // namespace refray
