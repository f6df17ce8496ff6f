#pragma once
/// @file
/// ClassLoader: finds plugin libraries on a search path, checks them, creates and owns instances.

#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/plugin.hpp>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

extern "C" struct ssx_plugin_class;

namespace ssx {

/// What a plugin class is: a robot's driver, a sensor, or a simulation extension.
enum class PluginKind : std::uint8_t { Driver, Sensor, Extension };
/// "driver", "sensor" or "extension".
SSX_EXPORT const char* toString(PluginKind kind);

/// A plugin could not be found, loaded, checked or instantiated. The message names the plugin,
/// every path tried and why each failed.
class SSX_EXPORT PluginError : public Error {
 public:
  using Error::Error;
};

/// What a plugin library holds, as read from its manifest.
struct PluginLibraryInfo {
  std::filesystem::path path;  ///< the library file
  bool ok = false;        ///< passes every check
  std::string problem;    ///< why not, when !ok
  std::string build_tag;  ///< as the library reports it
  /// One class the library offers.
  struct Class {
    PluginKind kind;              ///< driver, sensor or extension
    std::string name;             ///< its class name, as a scene names it (`class="..."`)
    std::string doc;              ///< one line on what it is ("" if the plugin gives none)
    std::string parameter_table;  ///< its declared parameters as a Markdown table (parameterTable)
  };
  std::vector<Class> classes;  ///< in the manifest's order
};

/// Loads plugin libraries with dlopen(RTLD_NOW | RTLD_LOCAL) and checks their manifest (ABI
/// version, record sizes, build tag, classes) before it creates anything from them.
///
/// What runs when: dlopen itself runs the library's static initialisers (and those of the
/// libraries it pulls in); no loader can check anything before that. Then the manifest is read
/// (`ssx_plugin_manifest_v1`, plain data) and checked; a library that fails is closed again
/// (dlclose) and none of its functions is called. A class's `create` runs only when an instance is
/// made: for a scene, after every check of the whole scene passed. `ssx plugins` inspects each
/// library in a child process of its own, so a library that crashes while loading is reported,
/// not fatal.
///
/// Ownership: the loader owns every instance it creates and destroys all of them (newest first)
/// in `destroyInstances()` or its destructor. It never unloads a library: callbacks, type
/// information and strings made by plugin code may outlive the instances (in other artifacts'
/// subscriptions, in exception messages), and unloading would buy nothing in a simulator process.
///
/// A plugin name ("hover") is looked up in each search directory, in order, as
/// `libssx_<name>.so`, `lib<name>.so` and `<name>.so`; a name with a '/' or ending in ".so" is a
/// file path, used as it is (the scene loader makes paths in scene files absolute first).
class SSX_EXPORT ClassLoader {
 public:
  ClassLoader();
  ~ClassLoader();
  ClassLoader(const ClassLoader&) = delete;
  ClassLoader& operator=(const ClassLoader&) = delete;

  /// Appends a directory to the search path (searched in the order added).
  void addSearchDirectory(std::filesystem::path dir);
  /// The directories searched for plugin libraries, in order.
  const std::vector<std::filesystem::path>& searchPath() const noexcept { return search_path_; }
  /// The plugin directory of this libssx installation (`<libdir>/ssx/plugins`, found beside the
  /// loaded libssx itself, so it works in a build tree and after install).
  static std::filesystem::path installedPluginDirectory();

  /// Finds, opens and checks a plugin library; returns its path. Loading the same library again
  /// is free. Throws PluginError.
  std::filesystem::path load(std::string_view plugin);
  /// Creates an instance of `class_name` from `plugin`, of the given kind. The loader owns it.
  /// Throws PluginError (unknown class, class of another kind, constructor threw or returned null).
  Driver& createDriver(std::string_view plugin, std::string_view class_name);
  /// @copydoc createDriver
  Sensor& createSensor(std::string_view plugin, std::string_view class_name);
  /// @copydoc createDriver
  SimulationExtension& createExtension(std::string_view plugin, std::string_view class_name);
  /// The manifest entry of `class_name` in `plugin` (loading the library), which must be of
  /// `kind`. Valid as long as the loader lives. Throws PluginError.
  const ssx_plugin_class& classInfo(std::string_view plugin, std::string_view class_name, PluginKind kind);
  /// The manifest entry of the class an instance made by this loader belongs to, or null.
  const ssx_plugin_class* classOf(const void* instance) const noexcept;

  /// Every library on the search path (files ending in .so), checked but not instantiated.
  std::vector<PluginLibraryInfo> scan() const;
  /// Checks one library file without keeping it loaded (if it fails) and without creating anything.
  static PluginLibraryInfo inspect(const std::filesystem::path& file);

  /// Destroys every instance created so far, newest first.
  void destroyInstances() noexcept;

 private:
  struct Library;
  void* create(std::string_view plugin, std::string_view class_name, PluginKind kind);

  std::vector<std::filesystem::path> search_path_;
  std::vector<std::unique_ptr<Library>> libraries_;
  std::unordered_map<std::string, const Library*> by_name_;  // plugin names already resolved
  struct Instance {
    void* object;
    const ssx_plugin_class* type;
    bool in_pool;  // made by `construct` in a pool below, else by `create`
  };
  std::vector<Instance> instances_;
  // a class's instances side by side: chunks of slots, each chunk twice the last (up to a cap)
  struct Pool {
    std::size_t slot = 0, align = 0;  // bytes per instance (whole cache lines) and alignment
    std::ptrdiff_t offset = -1;       // from a slot to the instance's address (its base class), once known
    std::vector<std::pair<std::byte*, std::size_t>> chunks;  // start, slots
    std::size_t used = 0;             // slots used in the last chunk
    void* next();                     // the next free slot (a new chunk when the last is full)
  };
  std::unordered_map<const ssx_plugin_class*, Pool> pools_;
  Pool& poolOf(const ssx_plugin_class& type);
  // classOf's tables: every pool's chunks by address (a swarm's instances need no entry each),
  // and the instances `create` made outside a pool
  struct ChunkOf {
    const std::byte* start;
    std::size_t chunk;  // its index in the pool
    const Pool* pool;
    const ssx_plugin_class* type;
  };
  std::vector<ChunkOf> chunks_by_address_;
  std::unordered_map<const void*, const ssx_plugin_class*> unpooled_;
  struct LastClass {
    std::string plugin, class_name;
    PluginKind kind{};
    const ssx_plugin_class* type = nullptr;
  } last_;  // the class create found last
};

}  // namespace ssx
