#include "core/hash.h"

#include <fstream>
#include <iterator>

#include <openssl/err.h>
#include <openssl/evp.h>

#include "core/error.h"
#include "core/file_input.h"

namespace refray {

namespace {

// OpenSSL's reason for the last failure, for the message.
std::string openSSLError() {
    char text[256] = "no reason given";
    if (const unsigned long code = ERR_get_error()) ERR_error_string_n(code, text, sizeof text);
    return text;
}

}  // namespace

struct Sha256::Context {
    std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> md{EVP_MD_CTX_new(), &EVP_MD_CTX_free};
};

Sha256::Sha256() : context_(std::make_unique<Context>()) {
    REFRAY_CHECK(context_->md && EVP_DigestInit_ex(context_->md.get(), EVP_sha256(), nullptr) == 1,
                 "OpenSSL cannot start a SHA-256 digest: " << openSSLError());
}

Sha256::~Sha256() = default;

Sha256& Sha256::update(const void* data, size_t size) {
    REFRAY_CHECK(EVP_DigestUpdate(context_->md.get(), data, size) == 1,
                 "OpenSSL's SHA-256 update failed: " << openSSLError());
    return *this;
}

std::array<uint8_t, 32> Sha256::digest() {
    std::array<uint8_t, 32> out;
    unsigned int size = 0;
    REFRAY_CHECK(EVP_DigestFinal_ex(context_->md.get(), out.data(), &size) == 1 && size == out.size(),
                 "OpenSSL's SHA-256 digest failed: " << openSSLError());
    return out;
}

std::string Sha256::hexDigest() {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (uint8_t b : digest()) s += digits[b >> 4], s += digits[b & 15];
    return s;
}

std::string sha256Hex(std::string_view bytes) { return Sha256().update(bytes).hexDigest(); }

std::string sha256HexOfFile(const std::filesystem::path& path) {
    return sha256Hex(readInputFile(path.string(), "file", kMaxImageInputBytes));
}

}  // namespace refray
