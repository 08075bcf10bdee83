#include "core/image_file.h"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <unistd.h>

#include <OpenImageIO/filesystem.h>

#include "core/error.h"
#include "core/file_input.h"
#include "core/file_output.h"

namespace refray {

namespace fs = std::filesystem;

std::unique_ptr<OIIO::ImageInput> openImageFile(const std::string& path, const std::string& what,
                                                const OIIO::ImageSpec& config) {
    checkInputFile(path, what, kMaxImageInputBytes);
    auto in = OIIO::ImageInput::open(path, &config);
    REFRAY_CHECK(in, "cannot read " << what << " '" << path << "' (corrupted or not an image): " << OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    REFRAY_CHECK(spec.width > 0 && spec.height > 0 && spec.depth > 0 && spec.nchannels > 0,
                 "cannot read " << what << " '" << path << "': it has no pixels");
    const uint64_t pixels = uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(spec.depth);
    // Pixels and samples: a 16384 x 16384 RGBA render is the most refray reads (4 GiB as floats); an image of more
    // channels (an envelope has 12) may have proportionally fewer pixels.
    REFRAY_CHECK(pixels <= kMaxImagePixels && pixels * uint64_t(spec.nchannels) <= kMaxImagePixels * 4,
                 "cannot read " << what << " '" << path << "': its header declares " << spec.width << "x"
                                << spec.height << " pixels (" << spec.nchannels << " channels), more than the "
                                << kMaxImagePixels << " pixels (16384x16384) refray reads; a file this small ("
                                << fs::file_size(path) << " bytes) that claims so much is corrupt or a "
                                                          "decompression bomb");
    return in;
}

namespace {

// Formats without an in-memory writer are encoded into a private file of the system's temporary folder and read back.
std::string encodeThroughTemporaryFile(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                                       const void* pixels) {
    static std::atomic<unsigned> counter{0};
    const fs::path temporary = fs::temp_directory_path() / ("refray-encode-" + std::to_string(::getpid()) + "-" +
                                                            std::to_string(counter++) +
                                                            fs::path(path).extension().string());
    struct Remove {
        fs::path p;
        ~Remove() {
            std::error_code ignored;
            fs::remove(p, ignored);
        }
    } remove{temporary};
    auto out = OIIO::ImageOutput::create(temporary.string());
    REFRAY_CHECK(out, "cannot write '" << path << "': " << OIIO::geterror());
    REFRAY_CHECK(out->open(temporary.string(), spec) && out->write_image(type, pixels) && out->close(),
                 "cannot write '" << path << "': encoding it failed: " << out->geterror());
    return readInputFile(temporary.string(), "encoded image", kMaxImageInputBytes);
}

}  // namespace

void writeImageFile(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type, const void* pixels) {
    checkOutputPath(path);
    auto out = OIIO::ImageOutput::create(path);
    REFRAY_CHECK(out, "cannot write '" << path << "': no image format for extension '"
                                       << fs::path(path).extension().string() << "' (" << OIIO::geterror() << ")");
    std::string bytes;
    if (out->supports("ioproxy")) {
        std::vector<unsigned char> buffer;
        OIIO::Filesystem::IOVecOutput proxy(buffer);
        REFRAY_CHECK(out->set_ioproxy(&proxy), "cannot write '" << path << "': " << out->geterror());
        REFRAY_CHECK(out->open(path, spec), "cannot write '" << path << "': " << out->geterror());
        REFRAY_CHECK(out->write_image(type, pixels), "cannot write pixels to '" << path << "': " << out->geterror());
        REFRAY_CHECK(out->close(), "cannot write '" << path << "': " << out->geterror());
        bytes.assign(buffer.begin(), buffer.end());
    } else {
        bytes = encodeThroughTemporaryFile(path, spec, type, pixels);
    }
    writeFileAtomically(path, bytes);
}

}  // namespace refray
