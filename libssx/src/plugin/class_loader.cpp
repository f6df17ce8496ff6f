#include <ssx/class_loader.hpp>
#include <ssx/plugin_abi.hpp>

#include "plugin/elf_check.hpp"

#include <cxxabi.h>
#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <new>
#include <system_error>

namespace ssx {

namespace fs = std::filesystem;

const char* toString(PluginKind kind) {
  switch (kind) {
    case PluginKind::Driver:
      return "driver";
    case PluginKind::Sensor:
      return "sensor";
    case PluginKind::Extension:
      return "extension";
  }
  return "?";
}

namespace {

constexpr const char* kManifestSymbol = "ssx_plugin_manifest_v1";
constexpr std::uint32_t kMaxClasses = 4096;
constexpr std::uint32_t kMaxParameters = 4096;
constexpr std::size_t kMaxInstanceBytes = std::size_t{64} << 20;

// dlerror text, with any undefined C++ symbol demangled so the user sees what is missing
std::string explainDlerror(const char* text) {
  std::string out = text != nullptr ? text : "unknown dlopen error";
  const std::string marker = "undefined symbol: ";
  const auto at = out.find(marker);
  if (at == std::string::npos) return out;
  const auto begin = at + marker.size();
  auto end = out.find_first_of(" ,\t\n", begin);
  if (end == std::string::npos) end = out.size();
  const std::string mangled = out.substr(begin, end - begin);
  int status = 0;
  char* demangled = abi::__cxa_demangle(mangled.c_str(), nullptr, nullptr, &status);
  if (status == 0 && demangled != nullptr) out += " (" + std::string(demangled) + ")";
  std::free(demangled);
  return out;
}

std::string withArticle(PluginKind kind) {
  return std::string(kind == PluginKind::Extension ? "an " : "a ") + toString(kind);
}

bool validKind(std::uint32_t k) { return k >= SSX_PLUGIN_DRIVER && k <= SSX_PLUGIN_EXTENSION; }

PluginKind toKind(std::uint32_t k) {
  return k == SSX_PLUGIN_DRIVER   ? PluginKind::Driver
         : k == SSX_PLUGIN_SENSOR ? PluginKind::Sensor
                                  : PluginKind::Extension;
}

// reads and checks a manifest; returns "" when it is good
std::string checkManifest(const ssx_plugin_manifest* m, PluginLibraryInfo& info) {
  if (m == nullptr)
    return "not an ssx plugin: it has no '" + std::string(kManifestSymbol) + "' symbol (use SSX_PLUGIN)";
  if (m->abi_version != SSX_PLUGIN_ABI_VERSION)
    return "plugin ABI version " + std::to_string(m->abi_version) + ", this ssx loads version " +
           std::to_string(SSX_PLUGIN_ABI_VERSION) + ": rebuild the plugin against this ssx";
  if (m->record_size != sizeof(ssx_plugin_manifest) || m->class_size != sizeof(ssx_plugin_class))
    return "manifest record sizes differ from this ssx's (" + std::to_string(m->record_size) + "/" +
           std::to_string(m->class_size) + " vs " + std::to_string(sizeof(ssx_plugin_manifest)) + "/" +
           std::to_string(sizeof(ssx_plugin_class)) + "): rebuild the plugin against this ssx";
  info.build_tag = m->build_tag != nullptr ? m->build_tag : "";
  if (info.build_tag != SSX_PLUGIN_BUILD_TAG)
    return "built for '" + info.build_tag + "', this ssx is '" + SSX_PLUGIN_BUILD_TAG +
           "': rebuild the plugin against this ssx";
  if (m->class_count > kMaxClasses || (m->class_count > 0 && m->classes == nullptr))
    return "manifest lists an invalid class table";
  for (std::uint32_t i = 0; i < m->class_count; ++i) {
    const ssx_plugin_class& c = m->classes[i];
    if (c.name == nullptr || c.create == nullptr || c.destroy == nullptr || !validKind(c.kind))
      return "manifest entry " + std::to_string(i) + " is incomplete (kind, name, create and destroy are required)";
    if (c.construct != nullptr &&
        (c.destruct == nullptr || c.instance_size == 0 || c.instance_size > kMaxInstanceBytes ||
         c.instance_align == 0 || (c.instance_align & (c.instance_align - 1)) != 0 || c.instance_align > 4096))
      return "class '" + std::string(c.name) +
             "': construct needs destruct, an instance size (at most 64 MiB) and a power-of-two alignment (at most "
             "4096)";
    if (c.param_count > kMaxParameters || (c.param_count > 0 && c.params == nullptr))
      return "class '" + std::string(c.name) + "' lists an invalid parameter table";
    for (std::uint32_t k = 0; k < c.param_count; ++k) {
      const ssx_plugin_param& p = c.params[k];
      if (p.name == nullptr || p.doc == nullptr || p.unit == nullptr || p.default_value == nullptr ||
          p.choices == nullptr || p.type < SSX_PARAM_BOOL || p.type > SSX_PARAM_CHOICE)
        return "class '" + std::string(c.name) + "': parameter " + std::to_string(k) +
               " is incomplete (name, type, unit, default, choices and doc are required; use ssx::param)";
    }
    info.classes.push_back({toKind(c.kind), c.name, c.doc != nullptr ? c.doc : "",
                            parameterTable({c.params, c.param_count})});
  }
  return {};
}

}  // namespace

struct ClassLoader::Library {
  fs::path path;
  void* handle = nullptr;
  const ssx_plugin_manifest* manifest = nullptr;
  PluginLibraryInfo info;
};

ClassLoader::ClassLoader() = default;

ClassLoader::~ClassLoader() { destroyInstances(); }

void ClassLoader::destroyInstances() noexcept {
  for (auto it = instances_.rbegin(); it != instances_.rend(); ++it)
    (it->in_pool ? it->type->destruct : it->type->destroy)(it->object);
  instances_.clear();
  unpooled_.clear();
  chunks_by_address_.clear();
  for (auto& [type, pool] : pools_)
    for (const auto& [start, slots] : pool.chunks) ::operator delete(start, std::align_val_t(pool.align));
  pools_.clear();
}

ClassLoader::Pool& ClassLoader::poolOf(const ssx_plugin_class& type) {
  Pool& pool = pools_[&type];
  if (pool.slot == 0) {
    // whole cache lines: an instance starts a line, and two threads stepping neighbouring
    // artifacts do not share one
    pool.align = std::max<std::size_t>(type.instance_align, 64);
    pool.slot = (type.instance_size + pool.align - 1) / pool.align * pool.align;
  }
  return pool;
}

void* ClassLoader::Pool::next() {
  if (chunks.empty() || used == chunks.back().second) {
    // (the first chunk holds one: a world of one robot, as each of a learning environment's
    // thousand copies is, keeps no room for fifteen more; a swarm's chunks double from there)
    constexpr std::size_t kFirst = 1, kMaxBytes = std::size_t{8} << 20;
    const std::size_t slots =
        chunks.empty() ? kFirst : std::max<std::size_t>(1, std::min(2 * chunks.back().second, kMaxBytes / slot));
    chunks.emplace_back(static_cast<std::byte*>(::operator new(slots * slot, std::align_val_t(align))), slots);
    used = 0;
  }
  return chunks.back().first + used * slot;
}

void ClassLoader::addSearchDirectory(fs::path dir) {
  if (std::find(search_path_.begin(), search_path_.end(), dir) == search_path_.end())
    search_path_.push_back(std::move(dir));
}

fs::path ClassLoader::installedPluginDirectory() {
  // the directory of the libssx that holds this very function, plus ssx/plugins
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&ClassLoader::installedPluginDirectory), &info) == 0 || info.dli_fname == nullptr)
    return {};
  std::error_code ec;
  const fs::path lib = fs::weakly_canonical(fs::path(info.dli_fname), ec);
  return lib.parent_path() / "ssx" / "plugins";
}

PluginLibraryInfo ClassLoader::inspect(const fs::path& file) {
  PluginLibraryInfo info;
  info.path = file;
  if (info.problem = detail::sharedLibraryProblem(file); !info.problem.empty()) return info;
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    info.problem = explainDlerror(dlerror());
    return info;
  }
  const auto* m = static_cast<const ssx_plugin_manifest*>(dlsym(handle, kManifestSymbol));
  info.problem = checkManifest(m, info);
  info.ok = info.problem.empty();
  // a library that fails is closed (what it reported was copied); one that passes stays loaded,
  // as every library the loader uses (see the class comment)
  if (!info.ok) dlclose(handle);
  return info;
}

fs::path ClassLoader::load(std::string_view plugin) {
  const std::string name(plugin);
  if (const auto it = by_name_.find(name); it != by_name_.end()) return it->second->path;
  // candidates in search order
  std::vector<fs::path> candidates;
  const bool is_path = name.find('/') != std::string::npos || (name.size() > 3 && name.ends_with(".so"));
  if (is_path) {
    candidates.emplace_back(name);
  } else {
    for (const auto& dir : search_path_)
      for (const std::string& file : {"libssx_" + name + ".so", "lib" + name + ".so", name + ".so"})
        candidates.push_back(dir / file);
  }
  std::string tried;
  for (const auto& candidate : candidates) {
    std::error_code ec;
    if (!fs::is_regular_file(candidate, ec)) {
      tried += "\n  " + candidate.string() + ": not found";
      continue;
    }
    const fs::path canonical = fs::weakly_canonical(candidate, ec);
    for (const auto& lib : libraries_) {
      if (lib->path != canonical) continue;
      by_name_.emplace(name, lib.get());
      return canonical;
    }
    auto lib = std::make_unique<Library>();
    lib->path = canonical;
    lib->info.path = canonical;
    // a broken file is an error message here, not a signal inside dlopen
    if (const std::string problem = detail::sharedLibraryProblem(canonical); !problem.empty()) {
      tried += "\n  " + candidate.string() + ": " + problem;
      continue;
    }
    lib->handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (lib->handle == nullptr) {
      tried += "\n  " + candidate.string() + ": " + explainDlerror(dlerror());
      continue;
    }
    lib->manifest = static_cast<const ssx_plugin_manifest*>(dlsym(lib->handle, kManifestSymbol));
    const std::string problem = checkManifest(lib->manifest, lib->info);
    if (!problem.empty()) {
      tried += "\n  " + candidate.string() + ": " + problem;
      dlclose(lib->handle);  // nothing of it is used: it failed before any of its classes was
      continue;
    }
    lib->info.ok = true;
    by_name_.emplace(name, lib.get());
    libraries_.push_back(std::move(lib));
    return canonical;
  }
  if (candidates.empty()) tried = "\n  (the search path is empty: add a plugin directory)";
  // a name near one of the plugins there are: a typing slip
  std::vector<std::string> present;
  for (const auto& dir : search_path_) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string file = entry.path().filename().string();
      if (file.starts_with("libssx_") && file.ends_with(".so")) present.push_back(file.substr(7, file.size() - 10));
    }
  }
  throw PluginError("plugin '" + name + "' could not be loaded" + didYouMean(name, present) + "; tried:" + tried);
}

const ssx_plugin_class& ClassLoader::classInfo(std::string_view plugin, std::string_view class_name,
                                               PluginKind kind) {
  const fs::path path = load(plugin);
  const Library* lib = by_name_.at(std::string(plugin));
  const ssx_plugin_class* found = nullptr;
  for (std::uint32_t i = 0; i < lib->manifest->class_count && found == nullptr; ++i)
    if (class_name == lib->manifest->classes[i].name) found = &lib->manifest->classes[i];
  if (found != nullptr && toKind(found->kind) == kind) return *found;
  // what went wrong, said only when it did (a swarm creates thousands of instances)
  const std::string where = "plugin '" + std::string(plugin) + "' (" + path.string() + ")";
  if (found == nullptr) {
    std::string available;
    std::vector<std::string> names;
    for (std::uint32_t i = 0; i < lib->manifest->class_count; ++i) {
      const ssx_plugin_class& c = lib->manifest->classes[i];
      available += std::string(available.empty() ? "" : ", ") + c.name + " (" + toString(toKind(c.kind)) + ")";
      names.emplace_back(c.name);
    }
    throw PluginError(where + " has no class '" + std::string(class_name) + "'" + didYouMean(class_name, names) +
                      "; it has: " + (available.empty() ? std::string("none") : available));
  }
    throw PluginError(where + ": class '" + std::string(class_name) + "' is " + withArticle(toKind(found->kind)) +
                      ", not " + withArticle(kind));
  return *found;
}

const ssx_plugin_class* ClassLoader::classOf(const void* instance) const noexcept {
  // in a pool: the chunk that starts last at or before the address, if the address is where an
  // instance of a used slot of it is
  const auto address = static_cast<const std::byte*>(instance);
  auto it = std::upper_bound(chunks_by_address_.begin(), chunks_by_address_.end(), address,
                             [](const std::byte* a, const ChunkOf& c) { return a < c.start; });
  if (it != chunks_by_address_.begin()) {
    const ChunkOf& c = *std::prev(it);
    const Pool& pool = *c.pool;
    const auto [start, slots] = pool.chunks[c.chunk];
    const std::size_t used = c.chunk + 1 == pool.chunks.size() ? pool.used : slots;
    const std::ptrdiff_t from_start = address - start - pool.offset;
    if (pool.offset >= 0 && from_start >= 0 && static_cast<std::size_t>(from_start) % pool.slot == 0 &&
        static_cast<std::size_t>(from_start) / pool.slot < used)
      return c.type;
  }
  const auto found = unpooled_.find(instance);
  return found == unpooled_.end() ? nullptr : found->second;
}

void* ClassLoader::create(std::string_view plugin, std::string_view class_name, PluginKind kind) {
  // a swarm creates one class thousands of times in a row: the last lookup is kept
  if (last_.type == nullptr || last_.kind != kind || last_.plugin != plugin || last_.class_name != class_name)
    last_ = {std::string(plugin), std::string(class_name), kind, &classInfo(plugin, class_name, kind)};
  const ssx_plugin_class* found = last_.type;
  char error[512];
  error[0] = '\0';
  // in the class's pool when it can be built in place (a slot a failed construct leaves is reused)
  Pool* pool = found->construct != nullptr ? &poolOf(*found) : nullptr;
  const std::size_t chunks_before = pool != nullptr ? pool->chunks.size() : 0;
  void* const slot = pool != nullptr ? pool->next() : nullptr;
  if (pool != nullptr && pool->chunks.size() != chunks_before) {
    // a new chunk: into the address table, in order
    const ChunkOf entry{pool->chunks.back().first, pool->chunks.size() - 1, pool, found};
    chunks_by_address_.insert(std::upper_bound(chunks_by_address_.begin(), chunks_by_address_.end(), entry,
                                               [](const ChunkOf& a, const ChunkOf& b) { return a.start < b.start; }),
                              entry);
  }
  void* object = pool != nullptr ? found->construct(slot, error, sizeof error) : found->create(error, sizeof error);
  if (object == nullptr)
    throw PluginError("plugin '" + std::string(plugin) + "' (" + load(plugin).string() + "): creating '" + std::string(class_name) + "' failed: " +
                      (error[0] != '\0' ? std::string(error) : std::string("the constructor returned null")));
  if (pool != nullptr) {
    ++pool->used;
    pool->offset = static_cast<std::byte*>(object) - static_cast<std::byte*>(slot);  // the same for every instance
  } else {
    unpooled_.emplace(object, found);
  }
  instances_.push_back({object, found, pool != nullptr});
  return object;
}

Driver& ClassLoader::createDriver(std::string_view plugin, std::string_view class_name) {
  return *static_cast<Driver*>(create(plugin, class_name, PluginKind::Driver));
}
Sensor& ClassLoader::createSensor(std::string_view plugin, std::string_view class_name) {
  return *static_cast<Sensor*>(create(plugin, class_name, PluginKind::Sensor));
}
SimulationExtension& ClassLoader::createExtension(std::string_view plugin, std::string_view class_name) {
  return *static_cast<SimulationExtension*>(create(plugin, class_name, PluginKind::Extension));
}

std::vector<PluginLibraryInfo> ClassLoader::scan() const {
  std::vector<PluginLibraryInfo> out;
  for (const auto& dir : search_path_) {
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".so") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) out.push_back(inspect(f));
  }
  return out;
}

}  // namespace ssx
