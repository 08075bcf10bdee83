// Image files through OpenImageIO, checked: opening one refuses what is not a file and a header that declares more
// pixels than refray reads, before any pixel is allocated; writing one encodes it in memory and hands the bytes to
// core/file_output.h, so that an image is never left half-written. For core's image formats (image, envelope,
// statistics image); OpenImageIO's types stay inside core.
#pragma once

#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

namespace refray {

// Opens `path` (described as `what`, e.g. "image") with `config`; throws refray::Error naming the file when it is not
// a regular file within kMaxImageInputBytes, is not an image, or declares more than kMaxImagePixels pixels.
std::unique_ptr<OIIO::ImageInput> openImageFile(const std::string& path, const std::string& what,
                                                const OIIO::ImageSpec& config);

// Encodes `pixels` (of `type`, laid out as `spec` says) in the format `path`'s extension names and writes the file
// whole or not at all (writeFileAtomically). Throws refray::Error naming `path`.
void writeImageFile(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type, const void* pixels);

}  // namespace refray
