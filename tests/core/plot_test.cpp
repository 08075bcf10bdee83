#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "core/draw.h"
#include "core/error.h"
#include "core/plot.h"

using namespace refray;
using namespace refray::plot;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
const vec4 kRed(0.9f, 0.1f, 0.1f, 1.0f);

std::string outputPath(const std::string& name) {
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    return std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + name;
}

bool near(vec4 a, vec4 b, float tolerance = 0.03f) { return glm::all(glm::lessThanEqual(glm::abs(a - b), vec4(tolerance))); }

bool fontAvailable() { return textExtent("0", 12).first > 0; }

vec4 pixelAt(const Image& image, const PlotLayout& layout, double x, double y) {
    return image.at(uint32_t(std::floor(layout.x.toPixel(x))), uint32_t(std::floor(layout.y.toPixel(y))));
}

Series series(std::vector<Point> points, bool connect = false, vec4 colour = kRed) {
    Series s;
    s.points = std::move(points);
    s.connect = connect;
    s.colour = colour;
    return s;
}

bool isGold(vec4 c) { return c.r > 0.9f && c.g > 0.65f && c.g < 0.85f && c.b < 0.2f; }

int goldPixelsAround(const Image& image, const PlotLayout& layout, double x, double y) {
    const int cx = int(layout.x.toPixel(x)), cy = int(layout.y.toPixel(y));
    int count = 0;
    for (int j = cy - 16; j <= cy + 16; ++j)
        for (int i = cx - 16; i <= cx + 16; ++i) count += isGold(image.at(uint32_t(i), uint32_t(j))) ? 1 : 0;
    return count;
}

}  // namespace

TEST(PlotTest, ParetoFrontKeepsTheNonDominatedPointsSortedByX) {
    const std::vector<Point> points{{3, 1, ""}, {1, 3, ""}, {2, 2, ""}, {2.5, 2.5, ""}, {4, 4, ""}, {3.5, 1, ""}};
    EXPECT_EQ(paretoFront(points), (std::vector<size_t>{1, 2, 0}));
}

TEST(PlotTest, ParetoFrontTiesAreDominated) {
    // Equal x: the larger y is dominated; equal y: the larger x is dominated.
    EXPECT_EQ(paretoFront({{1, 2, ""}, {1, 1, ""}}), (std::vector<size_t>{1}));
    EXPECT_EQ(paretoFront({{2, 1, ""}, {1, 1, ""}}), (std::vector<size_t>{1}));
}

TEST(PlotTest, ParetoFrontKeepsTheFirstOfDuplicates) {
    EXPECT_EQ(paretoFront({{5, 0, ""}, {1, 1, ""}, {1, 1, ""}, {0, 5, ""}}), (std::vector<size_t>{3, 1, 0}));
}

TEST(PlotTest, ParetoFrontNeverContainsNaN) {
    EXPECT_EQ(paretoFront({{kNaN, 0, ""}, {0, kNaN, ""}, {1, 1, ""}, {kNaN, kNaN, ""}}), (std::vector<size_t>{2}));
}

TEST(PlotTest, ParetoFrontOfEmptyAndSingleSets) {
    EXPECT_TRUE(paretoFront({}).empty());
    EXPECT_EQ(paretoFront({{7, 8, ""}}), (std::vector<size_t>{0}));
    EXPECT_TRUE(paretoFront({{kNaN, 8, ""}}).empty());
}

TEST(PlotTest, NiceTicksLinearUseOneTwoFiveSteps) {
    EXPECT_EQ(niceTicks(0, 1, false), (std::vector<double>{0, 0.2, 0.4, 0.6, 0.8, 1.0}));
    EXPECT_EQ(niceTicks(0, 10, false), (std::vector<double>{0, 2, 4, 6, 8, 10}));
    EXPECT_EQ(niceTicks(-3, 7, false), (std::vector<double>{-2, 0, 2, 4, 6}));
    EXPECT_EQ(niceTicks(-0.05, 1.05, false), (std::vector<double>{0, 0.2, 0.4, 0.6, 0.8, 1.0}));
    EXPECT_EQ(niceTicks(0.0012, 0.0047, false), (std::vector<double>{0.0015, 0.002, 0.0025, 0.003, 0.0035, 0.004, 0.0045}));
    EXPECT_EQ(niceTicks(120, 980, false), (std::vector<double>{200, 400, 600, 800}));
}

TEST(PlotTest, NiceTicksLogUseDecades) {
    EXPECT_EQ(niceTicks(0.003, 70, true), (std::vector<double>{0.01, 0.1, 1, 10}));
    EXPECT_EQ(niceTicks(1, 1000, true), (std::vector<double>{1, 10, 100, 1000}));
    // Many decades: at most eight labelled, all powers of ten.
    const std::vector<double> wide = niceTicks(1e-12, 1e12, true);
    EXPECT_LE(wide.size(), 8u);
    EXPECT_GE(wide.size(), 3u);
    for (double t : wide) EXPECT_NEAR(std::log10(t), std::round(std::log10(t)), 1e-12);
    // Less than three decades: 1-2-5 values.
    EXPECT_EQ(niceTicks(0.5, 30, true), (std::vector<double>{0.5, 1, 2, 5, 10, 20}));
    // Inside one decade: linear ticks.
    EXPECT_EQ(niceTicks(2, 8, true), (std::vector<double>{2, 3, 4, 5, 6, 7, 8}));
}

TEST(PlotTest, NiceTicksOfInvalidRangesAreEmpty) {
    EXPECT_TRUE(niceTicks(0, 10, true).empty());
    EXPECT_TRUE(niceTicks(-1, 10, true).empty());
    EXPECT_TRUE(niceTicks(kNaN, 1, false).empty());
    EXPECT_TRUE(niceTicks(0, kInf, false).empty());
    EXPECT_TRUE(niceTicks(2, 1, false).empty());
}

TEST(PlotTest, RenderedImageHasTheRequestedSize) {
    PlotSpec spec;
    spec.width = 640;
    spec.height = 400;
    spec.series.push_back(series({{0, 0, ""}, {1, 2, ""}}));
    const Image image = renderPlot(spec);
    EXPECT_EQ(image.width(), 640u);
    EXPECT_EQ(image.height(), 400u);
}

TEST(PlotTest, BadSizesAreErrors) {
    for (const auto& [w, h] : {std::pair(99, 300), std::pair(300, 99), std::pair(8193, 300), std::pair(300, 8193)}) {
        PlotSpec spec;
        spec.width = w;
        spec.height = h;
        try {
            renderPlot(spec);
            ADD_FAILURE() << "expected an error for " << w << "x" << h;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("outside 100..8192"), std::string::npos) << e.what();
        }
    }
    PlotSpec smallest;
    smallest.width = smallest.height = 100;
    EXPECT_NO_THROW(renderPlot(smallest));
}

TEST(PlotTest, MarkersAppearAtTheirMappedPixels) {
    PlotSpec spec;
    spec.series.push_back(series({{0, 0, ""}, {1, 1, ""}, {0.3, 0.7, ""}}));
    const PlotLayout layout = layoutPlot(spec);
    const Image image = renderPlot(spec);
    // Corners at 5% padding inside the box.
    EXPECT_NEAR(layout.x.toPixel(0) - layout.boxLeft, 0.05 / 1.1 * (layout.boxRight - layout.boxLeft) + 0.5, 1e-9);
    EXPECT_LT(layout.y.toPixel(1), layout.y.toPixel(0));
    for (const auto& [x, y] : {std::pair(0.0, 0.0), std::pair(1.0, 1.0), std::pair(0.3, 0.7)})
        EXPECT_TRUE(near(pixelAt(image, layout, x, y), kRed)) << x << ", " << y;
    EXPECT_FALSE(near(pixelAt(image, layout, 0.7, 0.3), kRed, 0.3f));
}

TEST(PlotTest, ConnectedSeriesDrawLinesBetweenPoints) {
    PlotSpec spec;
    spec.series.push_back(series({{0, 0, ""}, {1, 1, ""}}, true));
    const Image connected = renderPlot(spec);
    spec.series[0].connect = false;
    const Image loose = renderPlot(spec);
    const PlotLayout layout = layoutPlot(spec);
    EXPECT_TRUE(near(pixelAt(connected, layout, 0.5, 0.5), kRed, 0.4f));
    EXPECT_FALSE(near(pixelAt(loose, layout, 0.5, 0.5), kRed, 0.3f));
}

TEST(PlotTest, LogAxesSpaceDecadesEqually) {
    PlotSpec spec;
    spec.logX = spec.logY = true;
    spec.series.push_back(series({{0.01, 1e-6, ""}, {100, 1, ""}}));
    const PlotLayout layout = layoutPlot(spec);
    const double decadeX = layout.x.toPixel(0.1) - layout.x.toPixel(0.01);
    EXPECT_GT(decadeX, 10.0);
    for (double v : {0.1, 1.0, 10.0}) EXPECT_NEAR(layout.x.toPixel(v * 10) - layout.x.toPixel(v), decadeX, 1e-9);
    const double decadeY = layout.y.toPixel(1e-5) - layout.y.toPixel(1e-6);
    EXPECT_LT(decadeY, -10.0);
    EXPECT_NEAR(layout.y.toPixel(1) - layout.y.toPixel(0.1), decadeY, 1e-9);
    const Image image = renderPlot(spec);
    EXPECT_TRUE(near(pixelAt(image, layout, 0.01, 1e-6), kRed));
    EXPECT_TRUE(near(pixelAt(image, layout, 100, 1), kRed));
}

TEST(PlotTest, SkippedValuesNeitherCrashNorDraw) {
    PlotSpec clean;
    clean.logY = true;
    clean.series.push_back(series({{1, 1, ""}, {2, 10, ""}, {3, 5, ""}}, true));
    PlotSpec dirty = clean;
    auto& points = dirty.series[0].points;
    points.insert(points.begin(), {{kNaN, 1, ""}, {1, 0, ""}, {-kInf, 2, ""}});
    points.insert(points.end(), {{4, -1, ""}, {5, kNaN, ""}, {kInf, 3, ""}});
    dirty.series.push_back(series({{kNaN, kNaN, ""}, {2, 0, ""}}, true, vec4(0, 0, 1, 1)));
    dirty.highlights.push_back({kNaN, 1, "nowhere"});
    dirty.front = {{1, -3, ""}, {kInf, 1, ""}};
    const Image a = renderPlot(clean), b = renderPlot(dirty);
    const PlotLayout layoutA = layoutPlot(clean), layoutB = layoutPlot(dirty);
    EXPECT_EQ(layoutA.x.lo, layoutB.x.lo);
    EXPECT_EQ(layoutA.y.hi, layoutB.y.hi);
    EXPECT_TRUE(a.pixels() == b.pixels());

    // A skipped point breaks the line: no segment from (1, 1) to (3, 5) across the skipped (2, 0).
    PlotSpec broken = clean;
    broken.series[0].points = {{1, 1, ""}, {2, 0, ""}, {3, 5, ""}};
    const PlotLayout layout = layoutPlot(broken);
    EXPECT_FALSE(near(pixelAt(renderPlot(broken), layout, 2, std::sqrt(5.0)), kRed, 0.3f));
}

TEST(PlotTest, EmptyPlotDrawsAxesAndSaysNoData) {
    PlotSpec spec;
    spec.title = "nothing";
    spec.series.push_back(series({{kNaN, 1, ""}}));
    const PlotLayout layout = layoutPlot(spec);
    EXPECT_FALSE(layout.hasData);
    EXPECT_EQ(layout.x.lo, 0.0);
    EXPECT_EQ(layout.x.hi, 1.0);
    const Image image = renderPlot(spec);
    const vec4 corner = image.at(uint32_t(layout.boxLeft), uint32_t(layout.boxBottom));
    EXPECT_LT(corner.r, 0.3f);
    if (!fontAvailable()) GTEST_SKIP() << "no font: no text to find";
    int ink = 0;
    const int cx = (layout.boxLeft + layout.boxRight) / 2, cy = (layout.boxTop + layout.boxBottom) / 2;
    for (int y = cy - 12; y <= cy + 12; ++y)
        for (int x = cx - 40; x <= cx + 40; ++x) ink += image.at(uint32_t(x), uint32_t(y)).r < 0.6f ? 1 : 0;
    EXPECT_GT(ink, 20);
}

TEST(PlotTest, SingleOrEqualValuesGetASaneRange) {
    PlotSpec spec;
    spec.series.push_back(series({{5, 0, ""}, {5, 0, ""}}));
    PlotLayout layout = layoutPlot(spec);
    EXPECT_LT(layout.x.lo, 5.0);
    EXPECT_GT(layout.x.hi, 5.0);
    EXPECT_LT(layout.y.lo, 0.0);
    EXPECT_GT(layout.y.hi, 0.0);
    EXPECT_GE(layout.x.ticks.size(), 2u);
    EXPECT_TRUE(near(pixelAt(renderPlot(spec), layout, 5, 0), kRed));
    spec.logX = spec.logY = true;
    spec.series[0].points = {{3e-4, 2e9, ""}};
    layout = layoutPlot(spec);
    EXPECT_LT(layout.x.lo, 3e-4);
    EXPECT_GT(layout.x.hi, 3e-4);
    EXPECT_GT(layout.y.lo, 0.0);
    EXPECT_TRUE(near(pixelAt(renderPlot(spec), layout, 3e-4, 2e9), kRed));
}

TEST(PlotTest, HighlightsGetAGoldRing) {
    PlotSpec spec;
    spec.series.push_back(series({{0, 0, ""}, {0.5, 0.5, ""}, {1, 1, ""}}));
    const PlotLayout layout = layoutPlot(spec);
    EXPECT_EQ(goldPixelsAround(renderPlot(spec), layout, 0.5, 0.5), 0);
    spec.highlights.push_back({0.5, 0.5, "current default"});
    EXPECT_GT(goldPixelsAround(renderPlot(spec), layout, 0.5, 0.5), 40);
}

TEST(PlotTest, LegendAvoidsTheCornersWithData) {
    PlotSpec spec;
    Series crowded = series({}, false);
    crowded.name = "a long series name";
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            crowded.points.push_back({0.02 * i, 0.02 * j, ""});
            crowded.points.push_back({1 - 0.02 * i, 1 - 0.02 * j, ""});
            crowded.points.push_back({0.02 * i, 1 - 0.02 * j, ""});
        }
    spec.series.push_back(crowded);
    const PlotLayout layout = layoutPlot(spec);
    const Image image = renderPlot(spec);
    for (const Point& p : crowded.points) EXPECT_TRUE(near(pixelAt(image, layout, p.x, p.y), kRed)) << p.x << ", " << p.y;
}

TEST(PlotTest, SeriesColoursAreDistinctAndCycle) {
    for (size_t i = 0; i < 8; ++i)
        for (size_t j = i + 1; j < 8; ++j) EXPECT_NE(seriesColour(i), seriesColour(j)) << i << " " << j;
    EXPECT_EQ(seriesColour(3), seriesColour(11));
}

TEST(PlotTest, DemoPlotWritesAndReadsBack) {
    PlotSpec spec;
    spec.title = "Error vs time (demo sweep)";
    spec.xLabel = "render time [s]";
    spec.yLabel = "mean FLIP error";
    spec.logX = spec.logY = true;
    const char* names[] = {"spp sweep", "max depth sweep", "russian roulette"};
    const Marker markers[] = {Marker::Circle, Marker::Square, Marker::Diamond};
    std::vector<Point> all;
    for (int s = 0; s < 3; ++s) {
        Series line;
        line.name = names[s];
        line.marker = markers[s];
        line.labelPoints = s == 0;
        for (int k = 0; k < 7; ++k) {
            const double time = 0.004 * std::pow(2.2, k) * (1.0 + 0.35 * s);
            const double error = 0.3 / std::sqrt(std::pow(2.2, k)) * (1.0 + 0.25 * ((s + k) % 3)) + 0.002 * s;
            line.points.push_back({time, error, s == 0 ? std::to_string(1 << k) + " spp" : ""});
            all.push_back(line.points.back());
        }
        spec.series.push_back(line);
    }
    Series cross;
    cross.name = "other knobs";
    cross.connect = false;
    cross.marker = Marker::Cross;
    for (int k = 0; k < 6; ++k) cross.points.push_back({0.02 * (k + 1), 0.08 + 0.01 * k, ""});
    spec.series.push_back(cross);
    all.insert(all.end(), cross.points.begin(), cross.points.end());
    for (size_t i : paretoFront(all)) spec.front.push_back(all[i]);
    spec.highlights.push_back({spec.series[0].points[3].x, spec.series[0].points[3].y, "current default"});

    const Image image = renderPlot(spec);
    const std::string path = outputPath("plot_demo.png");
    writeImage(path, image);
    const Image back = readImage(path);
    ASSERT_EQ(back.width(), image.width());
    ASSERT_EQ(back.height(), image.height());
    const PlotLayout layout = layoutPlot(spec);
    EXPECT_TRUE(near(pixelAt(back, layout, cross.points[2].x, cross.points[2].y), seriesColour(3)));
    EXPECT_EQ(back.at(0, 0), vec4(1.0f));
}
