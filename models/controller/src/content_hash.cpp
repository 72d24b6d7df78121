// SHA-256 with OpenSSL's EVP interface (libcrypto, found by the top-level CMakeLists.txt), read
// in blocks so a large library is never held in memory whole.
#include "hiltwin/controller/content_hash.h"

#include <openssl/evp.h>

#include <array>
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller {
namespace {

struct DigestContextFree {
  void operator()(EVP_MD_CTX* context) const noexcept { EVP_MD_CTX_free(context); }
};

[[noreturn]] void Fail(const std::filesystem::path& file, const std::string& why) {
  throw ControllerError(file.string() + ": cannot hash the controller's file (" + why +
                        "): check that it is readable");
}

}  // namespace

std::string Sha256HexOfFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    Fail(file, std::strerror(errno));  // NOLINT(concurrency-mt-unsafe): start-up, one thread
  }
  const std::unique_ptr<EVP_MD_CTX, DigestContextFree> context(EVP_MD_CTX_new());
  if (!context || EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) != 1) {
    Fail(file, "OpenSSL could not start a SHA-256 digest");
  }
  constexpr std::size_t kBlockBytes = std::size_t{64} * 1024;
  std::array<char, kBlockBytes> block{};
  while (in) {
    in.read(block.data(), block.size());
    const std::streamsize got = in.gcount();
    if (got > 0 && EVP_DigestUpdate(context.get(), block.data(),
                                    static_cast<std::size_t>(got)) != 1) {
      Fail(file, "OpenSSL's SHA-256 update failed");
    }
  }
  if (in.bad()) {
    Fail(file, "a read failed");
  }
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(context.get(), digest.data(), &length) != 1) {
    Fail(file, "OpenSSL could not finish the SHA-256 digest");
  }
  static constexpr std::array<char, 16> kHex = {'0', '1', '2', '3', '4', '5', '6', '7',
                                                '8', '9', 'a', 'b', 'c', 'd', 'e', 'f'};
  std::string hex;
  hex.reserve(std::size_t{2} * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4U];
    hex += kHex[digest[i] & 0xFU];
  }
  return hex;
}

}  // namespace hiltwin::controller
