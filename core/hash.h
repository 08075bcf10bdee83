// SHA-256 (FIPS 180-4), for provenance: a golden image records the hash of the scene file it came from.
// OpenSSL's libcrypto computes it; its headers stay in core/hash.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace refray {

class Sha256 {
public:
    Sha256();
    ~Sha256();
    Sha256& update(const void* data, size_t size);
    Sha256& update(std::string_view text) { return update(text.data(), text.size()); }
    std::array<uint8_t, 32> digest();  // finishes; call once
    std::string hexDigest();           // lower-case hex of digest()

private:
    struct Context;  // OpenSSL's digest context
    std::unique_ptr<Context> context_;
};

std::string sha256Hex(std::string_view bytes);
// Throws refray::Error naming the file when it cannot be read.
std::string sha256HexOfFile(const std::filesystem::path& path);

}  // namespace refray
