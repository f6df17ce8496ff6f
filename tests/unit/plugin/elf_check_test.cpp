// Plugin libraries looked at before dlopen: a good one passes; a truncated copy, a file of text, a
// library for another machine and an ELF file that is no shared library each get a message that says
// what is wrong and what to do (dlopen would have raised SIGBUS for the first, and said "No such file
// or directory" for the third).
#include "plugin/elf_check.hpp"

#include <catch2/catch.hpp>

#include <elf.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace ssx::detail;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

const fs::path kGood = fs::path(SSX_TEST_PLUGIN_DIR) / "libssx_test_good.so";

std::string bytesOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path dir = fs::current_path() / "elf_check";
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
  return dir / name;
}

}  // namespace

TEST_CASE("elf check: a plugin built here passes", "[plugins][elf]") {
  CHECK(sharedLibraryProblem(kGood).empty());
}

TEST_CASE("elf check: a truncated copy is found before it is mapped", "[plugins][elf]") {
  const std::string good = bytesOf(kGood);
  REQUIRE(good.size() > 4096);
  for (std::size_t keep : {good.size() - 1, good.size() / 2, std::size_t{100}, std::size_t{10}}) {
    INFO("kept " << keep << " of " << good.size() << " bytes");
    CHECK_THAT(sharedLibraryProblem(write("cut.so", good.substr(0, keep))),
               Contains("truncated") && Contains("copy or build it again"));
  }
}

TEST_CASE("elf check: text, another machine, another kind of ELF file", "[plugins][elf]") {
  CHECK_THAT(sharedLibraryProblem(write("text.so", "this is not a library\n")), Contains("not a shared library (no ELF header"));
  CHECK_THAT(sharedLibraryProblem(write("empty.so", "")), Contains("no ELF header"));
  std::string other = bytesOf(kGood);
  auto& header = *reinterpret_cast<Elf64_Ehdr*>(other.data());
  const auto own = header.e_machine;
  header.e_machine = own == EM_AARCH64 ? EM_X86_64 : EM_AARCH64;
  CHECK_THAT(sharedLibraryProblem(write("other_machine.so", other)),
             Contains(own == EM_AARCH64 ? "built for x86-64" : "built for aarch64") && Contains("rebuild it here"));
  header.e_machine = own;
  header.e_type = ET_EXEC;
  CHECK_THAT(sharedLibraryProblem(write("program.so", other)), Contains("an ELF file of another kind"));
  CHECK_THAT(sharedLibraryProblem(fs::current_path() / "elf_check" / "none.so"), Contains("cannot open it"));
}
