#pragma once
// Why a file dlopen refused is not a library this process can load, read from its ELF header:
// glibc says "cannot open shared object file: No such file or directory" for a library built
// for another architecture, which sends a student looking for a file that is there.

#include <filesystem>
#include <string>

namespace hiltwin::controller {

/// A sentence saying what `file` is when its ELF header shows it cannot be loaded here: not an
/// ELF file, 32-bit in a 64-bit process, built for another machine, an object file or an
/// executable rather than a shared library. "" when the header looks loadable (the reason is
/// then elsewhere, such as a missing dependency) or the file cannot be read.
[[nodiscard]] std::string ExplainUnloadableElf(const std::filesystem::path& file);

}  // namespace hiltwin::controller
