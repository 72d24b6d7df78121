// The ELF header's identification, class, type and machine (<elf.h>), against this process's.
#include "elf_header.h"

#include <elf.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

namespace hiltwin::controller {
namespace {

#if defined(__x86_64__)
constexpr std::uint16_t kOwnMachine = EM_X86_64;
#elif defined(__aarch64__)
constexpr std::uint16_t kOwnMachine = EM_AARCH64;
#elif defined(__arm__)
constexpr std::uint16_t kOwnMachine = EM_ARM;
#elif defined(__i386__)
constexpr std::uint16_t kOwnMachine = EM_386;
#elif defined(__riscv)
constexpr std::uint16_t kOwnMachine = EM_RISCV;
#else
constexpr std::uint16_t kOwnMachine = EM_NONE;  // not known here: the machine is not compared
#endif
constexpr unsigned char kOwnClass = sizeof(void*) == 8 ? ELFCLASS64 : ELFCLASS32;

std::string MachineName(std::uint16_t machine) {
  switch (machine) {
    case EM_X86_64: return "x86-64 (amd64)";
    case EM_AARCH64: return "arm64 (aarch64)";
    case EM_ARM: return "32-bit arm (armhf)";
    case EM_386: return "32-bit x86 (i386)";
    case EM_RISCV: return "RISC-V";
    default: return "ELF machine " + std::to_string(machine);
  }
}

std::string Explain(const Elf64_Ehdr& header) {
  if (header.e_ident[EI_CLASS] != kOwnClass) {
    return std::string("it is a ") + (header.e_ident[EI_CLASS] == ELFCLASS32 ? "32" : "64") +
           "-bit ELF file and hiltwin is a " + (kOwnClass == ELFCLASS32 ? "32" : "64") +
           "-bit program: build the controller for this machine";
  }
  // e_type and e_machine sit at the same offsets in 32- and 64-bit headers.
  if (kOwnMachine != EM_NONE && header.e_machine != kOwnMachine) {
    return "it was built for " + MachineName(header.e_machine) + ", but this machine is " +
           MachineName(kOwnMachine) + ": build it here, or with a compiler for this machine";
  }
  if (header.e_type == ET_REL) {
    return "it is an object file (.o), not a shared library: link it with -shared "
           "(hiltwin_add_controller in CMake)";
  }
  if (header.e_type == ET_EXEC) {
    return "it is a program, not a shared library: build it with -shared -fPIC "
           "(hiltwin_add_controller in CMake)";
  }
  return "";
}

}  // namespace

std::string ExplainUnloadableElf(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in.is_open()) return "";
  Elf64_Ehdr header{};
  // A 32-bit header is shorter, but its identification, type and machine come first.
  in.read(reinterpret_cast<char*>(&header), sizeof header);
  const std::streamsize got = in.gcount();
  if (got < static_cast<std::streamsize>(EI_NIDENT) ||
      std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0) {
    return "it is not an ELF file, so not a shared library: give the .so the build made";
  }
  if (got < static_cast<std::streamsize>(sizeof(Elf32_Ehdr))) return "";
  return Explain(header);
}

}  // namespace hiltwin::controller
