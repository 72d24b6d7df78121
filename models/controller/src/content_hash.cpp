// SHA-256 of a file through OpenSSL's EVP interface (content_hash.h).
#include "hiltwin/controller/content_hash.h"

#include <openssl/evp.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller {
namespace {

[[noreturn]] void CannotHash(const std::filesystem::path& path, const std::string& why) {
  throw ControllerError("cannot compute the SHA-256 of " + path.string() + ": " + why +
                        "; give a readable file");
}

std::string Hex(const unsigned char* bytes, unsigned int size) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  out.reserve(static_cast<std::size_t>(size) * 2U);
  for (unsigned int i = 0; i < size; ++i) {
    out += kDigits[bytes[i] >> 4U];
    out += kDigits[bytes[i] & 0x0fU];
  }
  return out;
}

}  // namespace

std::string FileSha256(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    char buffer[256];
    CannotHash(path, strerror_r(errno, buffer, sizeof buffer));
  }
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(),
                                                                         &EVP_MD_CTX_free);
  if (!context || EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) != 1) {
    CannotHash(path, "OpenSSL could not start a SHA-256 digest");
  }
  std::array<char, 65536> chunk{};
  while (in) {
    in.read(chunk.data(), chunk.size());
    const std::streamsize got = in.gcount();
    if (got > 0 && EVP_DigestUpdate(context.get(), chunk.data(),
                                    static_cast<std::size_t>(got)) != 1) {
      CannotHash(path, "OpenSSL's SHA-256 digest failed");
    }
  }
  if (in.bad()) CannotHash(path, "a read failed part way");
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int size = 0;
  if (EVP_DigestFinal_ex(context.get(), digest.data(), &size) != 1) {
    CannotHash(path, "OpenSSL's SHA-256 digest failed");
  }
  return Hex(digest.data(), size);
}

}  // namespace hiltwin::controller
