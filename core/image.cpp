#include "core/image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "core/error.h"
#include "core/image_file.h"

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
    const bool asFloat = ext == ".exr" || ext == ".hdr" || ext == ".tif" || ext == ".tiff";
    OIIO::ImageSpec spec(int(image.width()), int(image.height()), 4,
                         asFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    for (const auto& [key, value] : image.metadata) spec.attribute(kMetadataPrefix + key, value);
    if (ext == ".exr") spec.attribute("compression", "zip");
    // A render target's alpha is just a fourth channel: store the colour bytes as they are, not divided by alpha
    // (OpenImageIO would otherwise treat our values as premultiplied and un-premultiply them for PNG).
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (asFloat) {
        writeImageFile(path, spec, OIIO::TypeDesc::FLOAT, image.pixels().data());
    } else {
        std::vector<uint8_t> bytes(image.pixels().size() * 4);
        for (size_t i = 0; i < image.pixels().size(); ++i)
            for (int c = 0; c < 4; ++c) bytes[i * 4 + c] = floatToUnorm8(image.pixels()[i][c]);
        writeImageFile(path, spec, OIIO::TypeDesc::UINT8, bytes.data());
    }
}

ImageHeader readImageHeader(const std::string& path) {
    OIIO::ImageSpec config;
    auto in = openImageFile(path, "image", config);
    return {uint32_t(in->spec().width), uint32_t(in->spec().height), uint32_t(in->spec().nchannels)};
}

Image readImage(const std::string& path) {
    // Read colour as stored, without premultiplying it by alpha (see writeImage).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = openImageFile(path, "image", config);
    const OIIO::ImageSpec& spec = in->spec();
    const int channels = spec.nchannels;
    std::vector<float> data;
    Image image;
    try {
        data.resize(size_t(spec.width) * spec.height * channels);
        image = Image(uint32_t(spec.width), uint32_t(spec.height));
    } catch (const std::bad_alloc&) {
        REFRAY_CHECK(false, "cannot read image '" << path << "': not enough memory for its " << spec.width << "x"
                                                   << spec.height << " pixels");
    }
    REFRAY_CHECK(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()),
                 "cannot read pixels of '" << path << "': " << in->geterror());

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
