// Texture2D (emulator/texture.cpp): D3D sampling rules over files read by OpenImageIO, and sampler validation.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "core/error.h"
#include "emulator/texture.h"
#include "harness.h"
#include "tests/test_output.h"

namespace refray::test {

using namespace refray::dxr;
namespace fs = std::filesystem;

namespace {

fs::path outputDir() { return refray::testing::testOutputDirectory("texture"); }

// Writes `texels` (width * height * channels floats, rows top to bottom) with OpenImageIO: .exr as 32-bit float,
// anything else as 8-bit (value * 255, rounded). With tileSize, a tiled file.
std::string writeTexture(const std::string& name, int width, int height, int channels, const std::vector<float>& texels,
                         int tileSize = 0) {
    const std::string path = (outputDir() / name).string();
    const bool exr = fs::path(name).extension() == ".exr";
    OIIO::ImageSpec spec(width, height, channels, exr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (tileSize) spec.tile_width = spec.tile_height = tileSize;
    spec.attribute("oiio:UnassociatedAlpha", 1);  // write alpha as given, without un-premultiplying colour
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out && out->open(path, spec)) << path << ": " << OIIO::geterror();
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, texels.data())) << out->geterror();
    out->close();
    return path;
}

// A width x height RGBA float texture whose texel (x, y) is (x, y, x + 10 y, 1) / scale.
std::string coordinateTexture(const std::string& name, int width, int height, float scale = 1.0f) {
    std::vector<float> texels;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            texels.insert(texels.end(), {float(x) / scale, float(y) / scale, float(x + 10 * y) / scale, 1.0f});
    return writeTexture(name, width, height, 4, texels);
}

SamplerDesc sampler(SamplerFilter filter, TextureAddressMode address = TEXTURE_ADDRESS_MODE_CLAMP) {
    SamplerDesc s;
    s.Filter = filter;
    s.AddressU = s.AddressV = s.AddressW = address;
    return s;
}

vec2 texelCentre(int x, int y, ivec2 size) {
    return {(float(x) + 0.5f) / float(size.x), (float(y) + 0.5f) / float(size.y)};
}

void expectNear(vec4 actual, vec4 expected, float tolerance = 1e-6f) {
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(actual[c], expected[c], tolerance) << "component " << c;
}

}  // namespace

TEST(Texture2D, PointSamplingReadsTheTexelUnderTheCoordinate) {
    const auto t = Texture2D::fromFile(coordinateTexture("coords_4x2.exr", 4, 2));
    EXPECT_EQ(t->width(), 4u);
    EXPECT_EQ(t->height(), 2u);
    EXPECT_EQ(t->fileChannels(), 4u);
    const SamplerDesc point = sampler(FILTER_MIN_MAG_MIP_POINT);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            EXPECT_EQ(t->SampleLevel(point, texelCentre(x, y, {4, 2}), 0.0f), vec4(x, y, x + 10 * y, 1))
                << x << "," << y;
    // A texel covers [i, i + 1) / size: its left edge belongs to it, its right edge to the next texel.
    EXPECT_EQ(t->SampleLevel(point, {0.25f, 0.25f}, 0.0f).x, 1.0f);
    EXPECT_EQ(t->SampleLevel(point, {0.2499f, 0.25f}, 0.0f).x, 0.0f);
    EXPECT_EQ(t->SampleLevel(point, {0.0f, 0.5f}, 0.0f).y, 1.0f);
}

TEST(Texture2D, BilinearSamplingBlendsTheFourNearestTexels) {
    const auto t = Texture2D::fromFile(coordinateTexture("coords_4x4.exr", 4, 4));
    const SamplerDesc linear = sampler(FILTER_MIN_MAG_MIP_LINEAR);
    // At a texel centre: the texel itself.
    EXPECT_EQ(t->SampleLevel(linear, texelCentre(1, 2, {4, 4}), 0.0f), vec4(1, 2, 21, 1));
    // On the edge between texels 1 and 2 of row 1: their mean.
    expectNear(t->SampleLevel(linear, {0.5f, 0.375f}, 0.0f), vec4(1.5f, 1, 11.5f, 1));
    // u * 4 - 0.5 = 0.7, v * 4 - 0.5 = 1.25: weights 0.3 / 0.7 across, 0.75 / 0.25 down.
    expectNear(t->SampleLevel(linear, {0.3f, 0.4375f}, 0.0f), vec4(0.7f, 1.25f, 0.7f + 12.5f, 1), 1e-5f);
    // Magnification uses the MAG filter, minification the MIN filter.
    const SamplerDesc magPoint = sampler(FILTER_MIN_LINEAR_MAG_MIP_POINT);
    EXPECT_EQ(t->SampleLevel(magPoint, {0.5f, 0.375f}, 0.0f).x, 2.0f);
    const SamplerDesc minPoint = sampler(FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT);
    expectNear(t->SampleLevel(minPoint, {0.5f, 0.375f}, 0.0f), vec4(1.5f, 1, 11.5f, 1));
}

TEST(Texture2D, EachAddressModeOutsideZeroToOne) {
    // One row of four texels, red 0.1 .. 0.4.
    const auto t = Texture2D::fromFile(
        writeTexture("row_4x1.exr", 4, 1, 4, {0.1f, 0, 0, 1, 0.2f, 0, 0, 1, 0.3f, 0, 0, 1, 0.4f, 0, 0, 1}));
    auto red = [&](TextureAddressMode mode, float u, SamplerFilter filter = FILTER_MIN_MAG_MIP_POINT) {
        return t->SampleLevel(sampler(filter, mode), {u, 0.5f}, 0.0f).x;
    };
    // Texel coordinates: u = 1.125 is texel 4, -0.125 texel -1, -0.375 texel -2, -1.375 texel -6, 2.125 texel 8.
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_WRAP, 1.125f), 0.1f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_WRAP, -0.125f), 0.4f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR, 1.125f), 0.4f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR, -0.125f), 0.1f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR, -1.375f), 0.3f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR, 2.125f), 0.1f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_CLAMP, 1.125f), 0.4f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_CLAMP, -7.0f), 0.1f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR_ONCE, -0.375f), 0.2f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR_ONCE, -1.375f), 0.4f);  // mirrored once, then clamped
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_MIRROR_ONCE, 1.125f), 0.4f);
    // WRAP across the edge with bilinear filtering blends the last and the first texel.
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_WRAP, 1.0f, FILTER_MIN_MAG_MIP_LINEAR), 0.25f);
    EXPECT_FLOAT_EQ(red(TEXTURE_ADDRESS_MODE_CLAMP, 1.0f, FILTER_MIN_MAG_MIP_LINEAR), 0.4f);

    // BORDER reads the sampler's border colour for texels outside, in every channel.
    for (StaticBorderColor colour :
         {STATIC_BORDER_COLOR_TRANSPARENT_BLACK, STATIC_BORDER_COLOR_OPAQUE_BLACK, STATIC_BORDER_COLOR_OPAQUE_WHITE}) {
        SamplerDesc border = sampler(FILTER_MIN_MAG_MIP_POINT, TEXTURE_ADDRESS_MODE_BORDER);
        border.BorderColor = toColor(colour);
        EXPECT_EQ(t->SampleLevel(border, {1.125f, 0.5f}, 0.0f), toColor(colour)) << colour;
        EXPECT_EQ(t->SampleLevel(border, {0.5f, -0.5f}, 0.0f), toColor(colour)) << colour;
        EXPECT_EQ(t->SampleLevel(border, {0.125f, 0.5f}, 0.0f), vec4(0.1f, 0, 0, 1)) << colour;
        // At the left edge, bilinear filtering weighs texel 0 and the border half and half.
        border.Filter = FILTER_MIN_MAG_MIP_LINEAR;
        expectNear(t->SampleLevel(border, {0.0f, 0.5f}, 0.0f), 0.5f * vec4(0.1f, 0, 0, 1) + 0.5f * toColor(colour));
    }
}

TEST(Texture2D, HigherMipLevelsHoldTheAverage) {
    // 4x4 float texture: level 1 is 2x2 box averages, level 2 the mean of all.
    std::vector<float> texels;
    for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {float(i), float(i % 4), 0.0f, 1.0f});
    const auto t = Texture2D::fromFile(writeTexture("ramp_4x4.exr", 4, 4, 4, texels));
    ASSERT_EQ(t->mipLevels(), 3u);
    EXPECT_EQ(t->width(1), 2u);
    EXPECT_EQ(t->height(2), 1u);
    EXPECT_EQ(t->width(3), 0u);
    const SamplerDesc point = sampler(FILTER_MIN_MAG_MIP_POINT);
    // Level 1 texel (1, 0) averages texels 2, 3, 6, 7.
    EXPECT_EQ(t->SampleLevel(point, {0.75f, 0.25f}, 1.0f), vec4(4.5f, 2.5f, 0, 1));
    EXPECT_EQ(t->Load({1, 0}, 1), vec4(4.5f, 2.5f, 0, 1));
    EXPECT_EQ(t->SampleLevel(point, {0.3f, 0.8f}, 2.0f), vec4(7.5f, 1.5f, 0, 1));
    EXPECT_EQ(t->SampleLevel(point, {0.3f, 0.8f}, 9.0f), vec4(7.5f, 1.5f, 0, 1));  // clamped to the last level
    // Texel (2, 0) of level 0 (red 2) lies in texel (1, 0) of level 1 (red 4.5).
    const vec2 uv(0.625f, 0.125f);
    // MIP point rounds the LOD to the nearest level; MIP linear blends the two around it by the fraction.
    EXPECT_EQ(t->SampleLevel(point, uv, 0.49f).x, 2.0f);
    EXPECT_EQ(t->SampleLevel(point, uv, 0.51f).x, 4.5f);
    const SamplerDesc mipLinear = sampler(FILTER_MIN_MAG_POINT_MIP_LINEAR);
    EXPECT_FLOAT_EQ(t->SampleLevel(mipLinear, uv, 0.25f).x, 0.75f * 2.0f + 0.25f * 4.5f);
    // MipLODBias adds to the LOD, MinLOD and MaxLOD clamp it.
    SamplerDesc biased = point;
    biased.MipLODBias = 1.0f;
    EXPECT_EQ(t->SampleLevel(biased, uv, 0.0f).x, 4.5f);
    SamplerDesc clamped = point;
    clamped.MinLOD = 2.0f;
    EXPECT_EQ(t->SampleLevel(clamped, uv, 0.0f).x, 7.5f);
    clamped.MinLOD = 0.0f;
    clamped.MaxLOD = 0.0f;
    EXPECT_EQ(t->SampleLevel(clamped, uv, 2.0f).x, 2.0f);

    // An 8-bit file: the average of 0, 64, 128 and 192 is 96 (exact in 8 bits).
    const auto png =
        Texture2D::fromFile(writeTexture("quad_2x2.png", 2, 2, 1, {0.0f, 64 / 255.0f, 128 / 255.0f, 192 / 255.0f}));
    ASSERT_EQ(png->mipLevels(), 2u);
    EXPECT_FLOAT_EQ(png->SampleLevel(point, {0.5f, 0.5f}, 1.0f).x, 96 / 255.0f);
    // Sizes halve and round down: 5x3 has levels 5x3, 2x1, 1x1.
    const auto odd = Texture2D::fromFile(writeTexture("odd_5x3.png", 5, 3, 1, std::vector<float>(15, 0.5f)));
    ASSERT_EQ(odd->mipLevels(), 3u);
    EXPECT_EQ(ivec2(odd->width(1), odd->height(1)), ivec2(2, 1));
}

TEST(Texture2D, SampleGradPicksTheLevelOfTheLongerDerivative) {
    std::vector<float> texels;
    for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {float(i), 0.0f, 0.0f, 1.0f});
    const auto t = Texture2D::fromFile(writeTexture("grad_4x4.exr", 4, 4, 4, texels));
    const SamplerDesc linear = sampler(FILTER_MIN_MAG_MIP_LINEAR);
    const vec2 uv(0.3f, 0.6f);
    // Two texels along x, half a texel along y: LOD log2(2) = 1.
    EXPECT_EQ(t->SampleGrad(linear, uv, {0.5f, 0.0f}, {0.0f, 0.125f}), t->SampleLevel(linear, uv, 1.0f));
    // The length of the derivative counts, not its components: (3, 4) texels is 5 long.
    expectNear(t->SampleGrad(linear, uv, {0.75f, 1.0f}, {0.0f, 0.0f}), t->SampleLevel(linear, uv, std::log2(5.0f)),
               1e-5f);
    // No derivatives: level 0.
    EXPECT_EQ(t->SampleGrad(linear, uv, {0.0f, 0.0f}, {0.0f, 0.0f}), t->SampleLevel(linear, uv, 0.0f));
}

TEST(Texture2D, AnisotropicFilteringKeepsDetailAcrossTheShortAxis) {
    // Vertical stripes one texel wide: a footprint 1 texel wide and 8 tall sees one stripe.
    std::vector<float> texels;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) texels.insert(texels.end(), {float(x % 2), 0.0f, 0.0f, 1.0f});
    const auto t = Texture2D::fromFile(writeTexture("stripes_16.exr", 16, 16, 4, texels));
    const vec2 uv = texelCentre(5, 8, {16, 16});
    const vec2 ddx(1.0f / 16, 0.0f), ddy(0.0f, 8.0f / 16);
    const float trilinear = t->SampleGrad(sampler(FILTER_MIN_MAG_MIP_LINEAR), uv, ddx, ddy).x;
    const float anisotropic = t->SampleGrad(sampler(FILTER_ANISOTROPIC, TEXTURE_ADDRESS_MODE_WRAP), uv, ddx, ddy).x;
    EXPECT_NEAR(trilinear, 0.5f, 1e-6f);  // LOD 3: every stripe averaged away
    EXPECT_GT(anisotropic, 0.9f) << "the elliptical filter should stay on the stripe";
    // OpenImageIO cannot express an opaque border: the documented fallback is trilinear at the derivative LOD.
    SamplerDesc opaqueBorder = sampler(FILTER_ANISOTROPIC, TEXTURE_ADDRESS_MODE_BORDER);
    opaqueBorder.BorderColor = vec4(1.0f);
    EXPECT_EQ(t->SampleGrad(opaqueBorder, uv, ddx, ddy).x, trilinear);
    // SampleLevel has no footprint to orient: anisotropic filters as MIN_MAG_MIP_LINEAR.
    EXPECT_EQ(t->SampleLevel(sampler(FILTER_ANISOTROPIC), uv, 1.5f),
              t->SampleLevel(sampler(FILTER_MIN_MAG_MIP_LINEAR), uv, 1.5f));
}

TEST(Texture2D, LoadReadsOneTexelAndZerosOutOfRange) {
    const auto t = Texture2D::fromFile(coordinateTexture("coords_3x2.exr", 3, 2));
    EXPECT_EQ(t->Load({2, 1}), vec4(2, 1, 12, 1));
    EXPECT_EQ(t->Load({3, 0}), vec4(0.0f));
    EXPECT_EQ(t->Load({-1, 0}), vec4(0.0f));
    EXPECT_EQ(t->Load({0, 2}), vec4(0.0f));
    EXPECT_EQ(t->Load({0, 0}, int(t->mipLevels())), vec4(0.0f));
    EXPECT_EQ(t->Load({0, 0}, -1), vec4(0.0f));
}

TEST(Texture2D, ReadLevelGivesEveryTexelAsLoadDoes) {
    std::vector<float> texels;
    for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {float(i), float(i % 4), 0.0f, 1.0f});
    const auto t = Texture2D::fromFile(writeTexture("readlevel_4x4.exr", 4, 4, 4, texels));
    for (uint32_t level = 0; level < t->mipLevels(); ++level) {
        const std::vector<vec4> all = t->readLevel(level);
        ASSERT_EQ(all.size(), size_t(t->width(level)) * t->height(level)) << level;
        for (uint32_t y = 0; y < t->height(level); ++y)
            for (uint32_t x = 0; x < t->width(level); ++x)
                EXPECT_EQ(all[y * t->width(level) + x], t->Load(ivec2(x, y), int(level))) << level << " " << x << " " << y;
    }
    // A grey sRGB file expands and decodes as Load does.
    const auto grey = Texture2D::fromFile(writeTexture("readlevel_grey.png", 2, 1, 1, {0.2f, 0.8f}), /*sRGB=*/true);
    EXPECT_EQ(grey->readLevel(0), (std::vector<vec4>{grey->Load({0, 0}), grey->Load({1, 0})}));
    EXPECT_THROW(t->readLevel(t->mipLevels()), Error);
}

TEST(Texture2D, ChannelsExpandToRgbaAndSrgbDecodesColourOnly) {
    const auto grey = Texture2D::fromFile(writeTexture("grey.png", 1, 1, 1, {51 / 255.0f}));
    EXPECT_EQ(grey->fileChannels(), 1u);
    expectNear(grey->Load({0, 0}), vec4(0.2f, 0.2f, 0.2f, 1.0f));
    const auto rgb = Texture2D::fromFile(writeTexture("rgb.png", 1, 1, 3, {1.0f, 0.0f, 0.2f}));
    expectNear(rgb->Load({0, 0}), vec4(1.0f, 0.0f, 0.2f, 1.0f));
    // Unpremultiplied alpha stays as stored.
    const auto rgba = Texture2D::fromFile(writeTexture("rgba.png", 1, 1, 4, {1.0f, 0.4f, 0.2f, 0.2f}));
    expectNear(rgba->Load({0, 0}), vec4(1.0f, 0.4f, 0.2f, 0.2f));
    const auto srgb = Texture2D::fromFile((outputDir() / "rgba.png").string(), /*sRGB=*/true);
    auto decode = [](float c) { return std::pow((c + 0.055f) / 1.055f, 2.4f); };  // c above 0.04045
    expectNear(srgb->Load({0, 0}), vec4(1.0f, decode(0.4f), decode(0.2f), 0.2f));
    const auto dark = Texture2D::fromFile(writeTexture("dark.png", 1, 1, 1, {5 / 255.0f}), /*sRGB=*/true);
    EXPECT_FLOAT_EQ(dark->Load({0, 0}).x, 5 / 255.0f / 12.92f);
}

TEST(Texture2D, AMissingOrCorruptFileFailsWhenTheTextureIsMade) {
    const std::string missing = (outputDir() / "no_such_texture.png").string();
    try {
        Texture2D::fromFile(missing);
        ADD_FAILURE() << "no error for a missing file";
    } catch (const Error& e) {
        const std::string m = e.what();
        // Refused before OpenImageIO opens it (core/file_input.h), with the OS's reason.
        EXPECT_NE(m.find("cannot read texture '" + missing + "': no such file or directory"), std::string::npos) << m;
    }
    const std::string corrupt = (outputDir() / "corrupt.png").string();
    std::ofstream(corrupt, std::ios::binary) << "this is not a PNG";
    try {
        Texture2D::fromFile(corrupt);
        ADD_FAILURE() << "no error for a corrupt file";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("texture '" + corrupt + "'"), std::string::npos) << e.what();
    }
}

TEST(Texture2D, ARewrittenFileIsReadAgain) {
    const std::string path = writeTexture("rewritten.exr", 1, 1, 4, {0.25f, 0, 0, 1});
    const auto first = Texture2D::fromFile(path);  // keeps the TextureSystem and its cache alive
    EXPECT_EQ(first->Load({0, 0}).x, 0.25f);
    writeTexture("rewritten.exr", 1, 1, 4, {0.75f, 0, 0, 1});
    EXPECT_EQ(Texture2D::fromFile(path)->Load({0, 0}).x, 0.75f);
}

TEST(Texture2D, ResultsDoNotDependOnTheThreadCount) {
    std::vector<float> texels;
    for (int i = 0; i < 64 * 64; ++i) texels.insert(texels.end(), {float(i % 7) / 7, float(i % 13) / 13, 0.5f, 1.0f});
    const auto t = Texture2D::fromFile(writeTexture("noise_64.exr", 64, 64, 4, texels, 16));
    const SamplerDesc samplers[] = {sampler(FILTER_MIN_MAG_MIP_LINEAR, TEXTURE_ADDRESS_MODE_WRAP),
                                    sampler(FILTER_ANISOTROPIC, TEXTURE_ADDRESS_MODE_MIRROR)};
    constexpr int kSamples = 400;
    auto run = [&](int first, int count, std::vector<vec4>& out) {
        for (int i = first; i < first + count; ++i) {
            const vec2 uv(float(i) * 0.0137f - 1.0f, float(i) * 0.0071f);
            const vec2 ddx(0.02f * float(i % 5), 0.001f), ddy(0.0f, 0.01f * float(i % 3));
            out[size_t(i)] =
                t->SampleGrad(samplers[i % 2], uv, ddx, ddy) + t->SampleLevel(samplers[0], uv, float(i % 7));
        }
    };
    std::vector<vec4> serial(kSamples), parallel(kSamples);
    run(0, kSamples, serial);
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k) threads.emplace_back(run, k * kSamples / 4, kSamples / 4, std::ref(parallel));
    for (auto& thread : threads) thread.join();
    for (int i = 0; i < kSamples; ++i) EXPECT_EQ(serial[size_t(i)], parallel[size_t(i)]) << i;
}

TEST(Texture2D, BIND_10_SamplersD3D12WouldRefuse) {
    auto refused = [](SamplerDesc s) {
        return expectDxrError("BIND-10", [&] { validateSamplerDesc(s, "sampler 'S'"); });
    };
    SamplerDesc s;
    s.Filter = SamplerFilter(0x80);  // a comparison filter
    EXPECT_NE(refused(s).format().find("sampler 'S': Filter is not a D3D12_FILTER refray models"), std::string::npos);
    s = {};
    s.AddressV = TextureAddressMode(0);
    EXPECT_NE(refused(s).format().find("AddressV = 0 (limit 1 (WRAP) .. 5 (MIRROR_ONCE))"), std::string::npos);
    s = {};
    s.MipLODBias = 16.0f;
    EXPECT_NE(refused(s).format().find("MipLODBias = 16 (limit [-16, 15.99])"), std::string::npos);
    s = {};
    s.Filter = FILTER_ANISOTROPIC;
    s.MaxAnisotropy = 0;
    EXPECT_NE(refused(s).format().find("MaxAnisotropy = 0 (limit 1..16)"), std::string::npos);
    s.MaxAnisotropy = 17;
    refused(s);
    s = {};
    s.MinLOD = 3.0f;
    s.MaxLOD = 2.0f;
    EXPECT_NE(refused(s).format().find("MinLOD must not exceed MaxLOD"), std::string::npos);
    validateSamplerDesc(SamplerDesc{}, "the default sampler");  // accepted
}

}  // namespace refray::test
