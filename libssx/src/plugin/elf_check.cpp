#include "plugin/elf_check.hpp"

#include <elf.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace ssx::detail {

namespace {

#if UINTPTR_MAX == 0xffffffffffffffffu
using Ehdr = Elf64_Ehdr;
using Phdr = Elf64_Phdr;
constexpr unsigned char kClass = ELFCLASS64;
#else
using Ehdr = Elf32_Ehdr;
using Phdr = Elf32_Phdr;
constexpr unsigned char kClass = ELFCLASS32;
#endif

std::string machineName(unsigned machine) {
  switch (machine) {
    case EM_X86_64: return "x86-64";
    case EM_386: return "x86 (32-bit)";
    case EM_AARCH64: return "aarch64";
    case EM_ARM: return "arm (32-bit)";
    case EM_RISCV: return "risc-v";
    case EM_PPC64: return "ppc64";
    case EM_S390: return "s390";
    default: return "machine " + std::to_string(machine);
  }
}

// the machine this code was compiled for (0: not known here, then not checked)
constexpr unsigned kOwnMachine =
#if defined(__x86_64__)
    EM_X86_64;
#elif defined(__aarch64__)
    EM_AARCH64;
#elif defined(__i386__)
    EM_386;
#elif defined(__arm__)
    EM_ARM;
#elif defined(__riscv)
    EM_RISCV;
#elif defined(__powerpc64__)
    EM_PPC64;
#elif defined(__s390x__)
    EM_S390;
#else
    0;
#endif

std::string bytes(std::uint64_t n) { return std::to_string(n) + " bytes"; }

}  // namespace

std::string sharedLibraryProblem(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return "cannot open it";
  const auto size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  unsigned char ident[EI_NIDENT] = {};
  in.read(reinterpret_cast<char*>(ident), EI_NIDENT);
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got < SELFMAG || std::memcmp(ident, ELFMAG, SELFMAG) != 0)
    return "not a shared library (no ELF header; " + bytes(size) + "): build the plugin, or copy it again";
  if (size < sizeof(Ehdr))
    return "truncated: " + bytes(size) + ", shorter than an ELF header (an interrupted copy?): copy or build it again";
  if (ident[EI_CLASS] != kClass)
    return std::string("built for another word size (") + (ident[EI_CLASS] == ELFCLASS32 ? "32" : "64") +
           "-bit; this process is " + (kClass == ELFCLASS32 ? "32" : "64") + "-bit): rebuild it for this machine";
  const unsigned char own_order = std::endian::native == std::endian::little ? ELFDATA2LSB : ELFDATA2MSB;
  if (ident[EI_DATA] != own_order) return "built for the other byte order: rebuild it for this machine";
  Ehdr header{};
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(&header), sizeof header)) return "cannot read its ELF header";
  if (header.e_type != ET_DYN) return "not a shared library (an ELF file of another kind): build the plugin as a module";
  if (constexpr unsigned own = kOwnMachine; own != 0 && header.e_machine != own)
    return "built for " + machineName(header.e_machine) + ", and this machine is " + machineName(own) +
           ": rebuild it here";
  // every table and loaded segment inside the file
  const auto ends = [&](std::uint64_t offset, std::uint64_t count, std::uint64_t entry) { return offset + count * entry; };
  const std::uint64_t program_end = ends(header.e_phoff, header.e_phnum, header.e_phentsize);
  const std::uint64_t section_end = ends(header.e_shoff, header.e_shnum, header.e_shentsize);
  const auto truncated = [&](const std::string& what, std::uint64_t end) {
    return "truncated: its " + what + " ends at byte " + std::to_string(end) + ", the file has " + bytes(size) +
           " (an interrupted copy?): copy or build it again";
  };
  if (program_end > size) return truncated("program header table", program_end);
  if (section_end > size) return truncated("section table", section_end);
  if (header.e_phentsize != sizeof(Phdr)) return "a malformed ELF file (program headers of an unknown size)";
  std::vector<Phdr> segments(header.e_phnum);
  in.seekg(static_cast<std::streamoff>(header.e_phoff));
  if (!segments.empty() && !in.read(reinterpret_cast<char*>(segments.data()),
                                    static_cast<std::streamsize>(segments.size() * sizeof(Phdr))))
    return truncated("program header table", program_end);
  for (const Phdr& p : segments)
    if (p.p_type == PT_LOAD && static_cast<std::uint64_t>(p.p_offset) + p.p_filesz > size)
      return truncated("loaded segment", static_cast<std::uint64_t>(p.p_offset) + p.p_filesz);
  return {};
}

}  // namespace ssx::detail
