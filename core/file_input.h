// Reading an input file only once it is known to be one: a regular file of a size refray documents, never a
// directory, a device (/dev/zero would be read until memory runs out), a FIFO or a socket.
#pragma once

#include <cstdint>
#include <string>

namespace refray {

// The largest text input refray reads (scene files, lessons, OBJ models, material libraries, manifests): 256 MiB.
inline constexpr uint64_t kMaxTextInputBytes = uint64_t(256) << 20;
// The largest image file refray opens (renders, goldens, envelopes, textures, masks): 2 GiB.
inline constexpr uint64_t kMaxImageInputBytes = uint64_t(2) << 30;
// The most pixels an image refray reads may declare in its header, checked before any pixel is allocated: as many as
// the largest render refray makes (16384 x 16384), and at most 4 times as many samples (pixels x channels).
inline constexpr uint64_t kMaxImagePixels = uint64_t(16384) * 16384;

// Throws refray::Error naming `what` and `path` unless `path` is a regular file of at most `maxBytes`:
// "cannot read scene file 'x': it is a directory, not a file".
void checkInputFile(const std::string& path, const std::string& what, uint64_t maxBytes);

// checkInputFile, then the whole file; a read error names the file and the OS's reason.
std::string readInputFile(const std::string& path, const std::string& what, uint64_t maxBytes = kMaxTextInputBytes);

// Whether `a` and `b` name the same file (through links, ".." and hard links); false when either does not exist.
bool sameFile(const std::string& a, const std::string& b);

}  // namespace refray
