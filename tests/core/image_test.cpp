#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/image.h"

using namespace refray;

namespace {
std::string outputPath(const std::string& name) {
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    return std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + name;
}
}  // namespace

TEST(Image, FloatToUnorm8FollowsTheD3DConversion) {
    EXPECT_EQ(floatToUnorm8(std::nanf("")), 0);
    EXPECT_EQ(floatToUnorm8(-1.0f), 0);
    EXPECT_EQ(floatToUnorm8(2.0f), 255);
    EXPECT_EQ(floatToUnorm8(0.5f), 128);  // 127.5 + 0.5 rounds up
    EXPECT_EQ(floatToUnorm8(1.0f / 255.0f), 1);
}

TEST(Image, ExrRoundTripKeepsFloatsAndMetadata) {
    Image image(3, 2, vec4(0.0f));
    image.at(2, 1) = vec4(1.5f, -0.25f, 3.0f, 0.5f);
    image.metadata["scene"] = "unit-test";
    const std::string path = outputPath("roundtrip.exr");
    writeImage(path, image);
    const Image back = readImage(path);
    ASSERT_EQ(back.width(), 3u);
    ASSERT_EQ(back.height(), 2u);
    EXPECT_EQ(back.at(2, 1), vec4(1.5f, -0.25f, 3.0f, 0.5f));
    EXPECT_EQ(back.metadata.at("scene"), "unit-test");
}

TEST(Image, PngStoresUnormBytes) {
    Image image(1, 1, vec4(0.5f, 2.0f, std::nanf(""), 1.0f));
    const std::string path = outputPath("unorm.png");
    writeImage(path, image);
    const Image back = readImage(path);
    EXPECT_FLOAT_EQ(back.at(0, 0).r, 128.0f / 255.0f);
    EXPECT_FLOAT_EQ(back.at(0, 0).g, 1.0f);
    EXPECT_FLOAT_EQ(back.at(0, 0).b, 0.0f);
}

TEST(Image, ReadingAMissingFileNamesIt) {
    try {
        readImage("/nonexistent/image.exr");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/image.exr"), std::string::npos);
    }
}

TEST(Image, WritingAnUnknownExtensionIsAnError) {
    EXPECT_THROW(writeImage(outputPath("image.unknownext"), Image(1, 1)), Error);
}

TEST(Image, PngKeepsColourBytesWhateverTheAlpha) {
    // A render target stores RGBA independently: alpha 0 or 0.5 must not change the stored colour.
    refray::Image image(2, 1);
    image.at(0, 0) = refray::vec4(0.2f, 0.4f, 0.6f, 0.5f);
    image.at(1, 0) = refray::vec4(0.8f, 0.6f, 0.4f, 0.0f);
    const std::string path = std::string(REFRAY_TEST_OUTPUT_DIR) + "/alpha.png";
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    refray::writeImage(path, image);
    const refray::Image back = refray::readImage(path);
    for (uint32_t x = 0; x < 2; ++x)
        for (int c = 0; c < 4; ++c)
            EXPECT_EQ(refray::floatToUnorm8(back.at(x, 0)[c]), refray::floatToUnorm8(image.at(x, 0)[c])) << x << " " << c;
}
