#include "core/image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "core/error.h"

namespace refray {

namespace {

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// Metadata keys live under a "refray:" prefix in the file so they never collide with
// the format's own attributes.
constexpr const char* kMetadataPrefix = "refray:";

}  // namespace

Image::Image(uint32_t width, uint32_t height, vec4 fill)
    : width_(width), height_(height), pixels_(size_t(width) * height, fill) {}

uint8_t floatToUnorm8(float value) {
    if (std::isnan(value)) return 0;
    const float clamped = std::clamp(value, 0.0f, 1.0f);
    return uint8_t(clamped * 255.0f + 0.5f);
}

void writeImage(const std::string& path, const Image& image) {
    REFRAY_CHECK(!image.empty(), "cannot write '" << path << "': the image is empty");
    const std::string ext = lowerExtension(path);
    auto out = OIIO::ImageOutput::create(path);
    REFRAY_CHECK(out, "cannot write '" << path << "': no image format for extension '" << ext
                                       << "' (" << OIIO::geterror() << ")");
    const bool asFloat = ext == ".exr" || ext == ".hdr" || ext == ".tif" || ext == ".tiff";
    OIIO::ImageSpec spec(int(image.width()), int(image.height()), 4,
                         asFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    for (const auto& [key, value] : image.metadata) spec.attribute(kMetadataPrefix + key, value);
    if (ext == ".exr") spec.attribute("compression", "zip");
    // A render target's alpha is just a fourth channel: store the colour bytes as they are, not divided by alpha
    // (OpenImageIO would otherwise treat our values as premultiplied and un-premultiply them for PNG).
    spec.attribute("oiio:UnassociatedAlpha", 1);
    REFRAY_CHECK(out->open(path, spec), "cannot open '" << path << "' for writing: " << out->geterror());

    bool ok = false;
    if (asFloat) {
        ok = out->write_image(OIIO::TypeDesc::FLOAT, image.pixels().data());
    } else {
        std::vector<uint8_t> bytes(image.pixels().size() * 4);
        for (size_t i = 0; i < image.pixels().size(); ++i)
            for (int c = 0; c < 4; ++c) bytes[i * 4 + c] = floatToUnorm8(image.pixels()[i][c]);
        ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    }
    REFRAY_CHECK(ok, "cannot write pixels to '" << path << "': " << out->geterror());
    REFRAY_CHECK(out->close(), "cannot close '" << path << "': " << out->geterror());
}

Image readImage(const std::string& path) {
    REFRAY_CHECK(std::filesystem::exists(path), "cannot read image '" << path << "': no such file");
    // Read colour as stored, without premultiplying it by alpha (see writeImage).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    REFRAY_CHECK(in, "cannot read image '" << path << "': " << OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    REFRAY_CHECK(spec.width > 0 && spec.height > 0 && spec.nchannels > 0,
                 "cannot read image '" << path << "': it has no pixels");
    const int channels = spec.nchannels;
    std::vector<float> data(size_t(spec.width) * spec.height * channels);
    REFRAY_CHECK(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()),
                 "cannot read pixels of '" << path << "': " << in->geterror());

    Image image(uint32_t(spec.width), uint32_t(spec.height));
    for (size_t i = 0; i < image.pixels().size(); ++i) {
        const float* p = &data[i * channels];
        vec4 v;
        if (channels == 1) v = vec4(p[0], p[0], p[0], 1.0f);
        else if (channels == 2) v = vec4(p[0], p[0], p[0], p[1]);
        else if (channels == 3) v = vec4(p[0], p[1], p[2], 1.0f);
        else v = vec4(p[0], p[1], p[2], p[3]);
        image.pixels()[i] = v;
    }
    const std::string prefix = kMetadataPrefix;
    for (const auto& attribute : spec.extra_attribs) {
        const std::string name = attribute.name().string();
        if (name.rfind(prefix, 0) == 0) image.metadata[name.substr(prefix.size())] = attribute.get_string();
    }
    return image;
}

}  // namespace refray
