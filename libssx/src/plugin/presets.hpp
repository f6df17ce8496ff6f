#pragma once
// Presets: files of parameter values a plugin's parameters start from. A plugin class that
// declares a text parameter named `preset` takes them: `preset="crazyflie"` on a quadrotor's driver
// reads `<dir>/quadrotor/crazyflie.xml` from the first preset directory that has it (the folder is
// the family the declaration's `choices` names, else the class's name: a class flying the
// quadrotor's vehicle declares its `preset` with choices "quadrotor"), beside the artifact
// types: `<artifact dir>/presets`, then the installed `<data>/presets`), or a file when the value
// is a path (`preset="my_quad.xml"`, relative to the file that says it). Every value the element
// does not give itself is taken from the preset, with the preset file's line as where it was
// written, then checked against the class's declarations like any other. The class's default
// preset writes out its own defaults: when its file is not found (a libssx without its data
// directory), the class's defaults stand in for it.
//
//   <preset class="quadrotor">
//     <!-- where the value comes from -->
//     <param name="thrust_coefficient" value="2.27e-8"/>
//   </preset>
//
// A user adds a vehicle by writing such a file; the built-in ones are in examples/presets.
#include <ssx/descriptor.hpp>
#include <ssx/error.hpp>
#include <ssx/plugin_abi.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace ssx::detail {

class Presets {
 public:
  /// `dirs`: the preset directories, searched in order (each holds one folder per class).
  Presets(std::vector<std::filesystem::path> dirs, std::uintmax_t max_bytes);

  /// If the class declares `preset`, sets on `params` every value of the preset it names (the
  /// attribute, else the declared default) that `params` does not give. Problems come back as
  /// diagnostics (nothing is set then); `used` gets the preset file read, if one was.
  std::vector<Diagnostic> apply(Descriptor& params, const char* class_name,
                                std::span<const ssx_plugin_param> declarations, const std::string& what,
                                std::filesystem::path* used = nullptr);

  /// What a plugin instance made by a program (not by the scene loader) is checked with before it
  /// runs: the preset it names applied, its parameters against the class's declarations, then the
  /// class's own validate. Errors and warnings, their messages starting with `what`.
  std::vector<Diagnostic> checkInstance(Descriptor& params, const ssx_plugin_class& type, const PluginContext& context,
                                        const std::string& what);

  /// The presets of a class found in the directories, by name, sorted (for messages and listings).
  std::vector<std::string> available(const std::string& class_name) const;

  /// The presets installed with libssx (installedDirectory(), when there is one).
  static Presets installed();
  /// The installed preset directory (installedDataDirectory()/presets), or empty.
  static std::filesystem::path installedDirectory();

 private:
  struct File {
    std::vector<Descriptor::Attribute> values;  // in file order
    std::string problem;                        // "file:line: error: ..." text, when it cannot be used
    SourceLocation problem_at;
  };
  // a preset file of a family, its form checked (by file and family, cached)
  const File& read(const std::filesystem::path& file, const std::string& family);

  std::vector<std::filesystem::path> dirs_;
  std::uintmax_t max_bytes_;
  std::map<std::string, File> cache_;  // by file and class
};

}  // namespace ssx::detail
