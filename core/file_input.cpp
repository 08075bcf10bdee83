#include "core/file_input.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include <sys/stat.h>

#include "core/error.h"
#include "core/os_error.h"

namespace refray {

namespace fs = std::filesystem;

namespace {

std::string sizeText(uint64_t bytes) {
    if (bytes >= (uint64_t(1) << 30) && bytes % (uint64_t(1) << 30) == 0) return std::to_string(bytes >> 30) + " GiB";
    if (bytes >= (uint64_t(1) << 20) && bytes % (uint64_t(1) << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
    return std::to_string(bytes) + " bytes";
}

}  // namespace

void checkInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
    struct stat s {};
    REFRAY_CHECK(!path.empty(), "cannot read " << what << ": the file name is empty");
    REFRAY_CHECK(::stat(path.c_str(), &s) == 0, "cannot read " << what << " '" << path << "': " << osReason(errno));
    const char* kind = S_ISDIR(s.st_mode)                        ? "a directory"
                       : S_ISCHR(s.st_mode) || S_ISBLK(s.st_mode) ? "a device"
                       : S_ISFIFO(s.st_mode)                      ? "a FIFO"
                       : S_ISSOCK(s.st_mode)                      ? "a socket"
                       : S_ISREG(s.st_mode)                       ? nullptr
                                                                  : "not a regular file";
    REFRAY_CHECK(!kind, "cannot read " << what << " '" << path << "': it is " << kind << ", not a file");
    REFRAY_CHECK(uint64_t(s.st_size) <= maxBytes, "cannot read " << what << " '" << path << "': it holds "
                                                                 << uint64_t(s.st_size) << " bytes, more than the "
                                                                 << sizeText(maxBytes) << " refray reads");
}

std::string readInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
    checkInputFile(path, what, maxBytes);
    struct FileCloser {
        void operator()(std::FILE* file) const { std::fclose(file); }
    };
    errno = 0;
    std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
    REFRAY_CHECK(file, "cannot read " << what << " '" << path << "': " << osReason(errno));
    std::string text;
    char buffer[1 << 16];
    size_t count = 0;
    // The size was checked above; a file growing while it is read is still cut off at the limit.
    while ((count = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) {
        text.append(buffer, count);
        REFRAY_CHECK(text.size() <= maxBytes, "cannot read " << what << " '" << path << "': it grew past the "
                                                             << sizeText(maxBytes) << " refray reads");
    }
    REFRAY_CHECK(!std::ferror(file.get()), "cannot read " << what << " '" << path << "': " << osReason(errno));
    return text;
}

bool sameFile(const std::string& a, const std::string& b) {
    std::error_code error;
    return fs::equivalent(a, b, error) && !error;
}

}  // namespace refray
