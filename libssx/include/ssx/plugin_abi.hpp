#pragma once
/// @file
/// The binary interface between libssx and plugin libraries, and the macro that writes it.
///
/// A plugin library exports one C data symbol, `ssx_plugin_manifest_v1`, of type
/// `ssx_plugin_manifest`: plain constant data (no code runs to produce it) giving the ABI version,
/// the record sizes, a build tag, and for every class its kind, name, `noexcept` create /
/// destroy functions, one line of doc and its declared parameters (ssx/parameters.hpp). The
/// ClassLoader reads and checks all of it before calling any plugin code.
///
/// A plugin author writes, in one .cpp of the library:
///
///     SSX_PLUGIN(SSX_DRIVER(HoverDriver, "hover"),
///                SSX_SENSOR(PoseSensor, "pose"))
///
/// Types must be default-constructible and derive from ssx::Driver, ssx::Sensor or
/// ssx::SimulationExtension respectively. A type may have these static members, which the
/// manifest then carries:
///   static constexpr ssx_plugin_param kParameters[] = {...};   // its parameters
///   static constexpr const char* kDoc = "...";                 // one line on what it is
///   static void validate(const ssx::Descriptor&, const ssx::PluginContext&);  // load-time checks

#include <ssx/parameters.hpp>
#include <ssx/plugin.hpp>
#include <ssx/version.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <iterator>
#include <new>
#include <type_traits>
#include <vector>

/// Incremented whenever the manifest layout, the meaning of its fields, the plugin base classes
/// (Plugin, Driver, Sensor, SimulationExtension: their virtual functions and members) or the
/// members of the classes whose inline accessors plugins compile in (Artifact, StateWriter) or the
/// structs handed to them (PluginContext) change.
#define SSX_PLUGIN_ABI_VERSION 11u

/// @cond
#define SSX_PLUGIN_STRINGIFY2(x) #x
/// @endcond
/// The text of a macro's value ("12" for a macro defined as 12).
#define SSX_PLUGIN_STRINGIFY(x) SSX_PLUGIN_STRINGIFY2(x)
/// The compiler a plugin (or libssx) was built with and its major version ("gcc 12").
#if defined(__clang__)
#define SSX_PLUGIN_COMPILER "clang " SSX_PLUGIN_STRINGIFY(__clang_major__)
#elif defined(__GNUC__)
#define SSX_PLUGIN_COMPILER "gcc " SSX_PLUGIN_STRINGIFY(__GNUC__)
#else
#define SSX_PLUGIN_COMPILER "unknown"
#endif
/// The C++ standard library and its ABI ("libstdc++ abi1"): plugins must match libssx's.
#if defined(_GLIBCXX_USE_CXX11_ABI)
#define SSX_PLUGIN_STDLIB "libstdc++ abi" SSX_PLUGIN_STRINGIFY(_GLIBCXX_USE_CXX11_ABI)
#elif defined(_LIBCPP_VERSION)
#define SSX_PLUGIN_STDLIB "libc++"
#else
#define SSX_PLUGIN_STDLIB "unknown"
#endif
/// What a plugin must have been built against to be loaded: the ssx major.minor version and the
/// C++ ABI (a class layout or standard-library mismatch would crash at run time instead).
#define SSX_PLUGIN_BUILD_TAG \
  "ssx " SSX_PLUGIN_STRINGIFY(SSX_VERSION_MAJOR) "." SSX_PLUGIN_STRINGIFY(SSX_VERSION_MINOR) "; " SSX_PLUGIN_STDLIB

extern "C" {

/// What a class in a plugin is.
enum ssx_plugin_kind : std::uint32_t {
  SSX_PLUGIN_DRIVER = 1,
  SSX_PLUGIN_SENSOR = 2,
  SSX_PLUGIN_EXTENSION = 3,
};

/// One class. `create` returns a new instance (as ssx::Driver*, ssx::Sensor* or
/// ssx::SimulationExtension*, by kind) or null, writing the reason into `error` (NUL-terminated,
/// at most `error_size` bytes); it never throws. `destroy` deletes an instance `create` returned.
/// `params` lists the `param_count` declared parameters. `validate`, when not null, checks a
/// parameter set (an `ssx::Descriptor*`, defaults added) in a context (an `ssx::PluginContext*`)
/// and appends what is wrong to `diagnostics` (a `std::vector<ssx::Diagnostic>*`); it runs no
/// instance's code and never throws.
/// `construct`, when not null, is `create` in memory the library provides: `instance_size` bytes
/// aligned to `instance_align` (a power of two); `destruct` ends an instance it made without
/// freeing that memory. The library keeps a class's instances side by side this way, so that a
/// phase walking thousands of them reads memory in order.
struct ssx_plugin_class {
  std::uint32_t kind;  ///< an ssx_plugin_kind
  const char* name;    ///< the class name scenes use
  void* (*create)(char* error, std::size_t error_size) noexcept;  ///< a new instance, or null and a reason
  void (*destroy)(void* instance) noexcept;                       ///< deletes what create returned
  const char* doc;                 ///< one line on what the class is, or null
  const ssx_plugin_param* params;  ///< its declared parameters (param_count of them)
  std::uint32_t param_count;       ///< how many declared parameters
  /// checks parameters in a context before anything runs, or null
  void (*validate)(const void* params, const void* context, void* diagnostics) noexcept;
  std::size_t instance_size;   ///< bytes construct needs (0: no construct)
  std::size_t instance_align;  ///< their alignment, a power of two
  /// create in memory the library provides, or null
  void* (*construct)(void* where, char* error, std::size_t error_size) noexcept;
  void (*destruct)(void* instance) noexcept;  ///< ends what construct made, without freeing
};

/// The manifest. `record_size` is sizeof(ssx_plugin_manifest) and `class_size` is
/// sizeof(ssx_plugin_class) as the plugin saw them.
struct ssx_plugin_manifest {
  std::uint32_t abi_version;        ///< SSX_PLUGIN_ABI_VERSION as the plugin was built
  std::uint32_t record_size;        ///< sizeof(ssx_plugin_manifest) as the plugin saw it
  std::uint32_t class_size;         ///< sizeof(ssx_plugin_class) as the plugin saw it
  std::uint32_t class_count;        ///< how many classes
  const char* build_tag;            ///< SSX_PLUGIN_BUILD_TAG as the plugin was built
  const ssx_plugin_class* classes;  ///< the classes (class_count of them)
};

}  // extern "C"

namespace ssx::detail {

// runs `make`, turning an exception into null and its message in `error`
template <class Make>
void* pluginMake(char* error, std::size_t error_size, Make make) noexcept {
  auto report = [&](const char* what) {
    if (error != nullptr && error_size > 0) {
      std::strncpy(error, what, error_size - 1);
      error[error_size - 1] = '\0';
    }
  };
  try {
    return make();
  } catch (const std::exception& e) {
    report(e.what());
  } catch (...) {
    report("unknown exception");
  }
  return nullptr;
}

template <class T, class Base>
void* pluginCreate(char* error, std::size_t error_size) noexcept {
  return pluginMake(error, error_size, [] { return static_cast<void*>(static_cast<Base*>(new T())); });
}

template <class Base>
void pluginDestroy(void* instance) noexcept {
  delete static_cast<Base*>(instance);
}

template <class T, class Base>
void* pluginConstruct(void* where, char* error, std::size_t error_size) noexcept {
  return pluginMake(error, error_size, [where] { return static_cast<void*>(static_cast<Base*>(::new (where) T())); });
}

template <class Base>
void pluginDestruct(void* instance) noexcept {
  static_cast<Base*>(instance)->~Base();  // virtual: the class's own destructor
}

template <class T>
void pluginValidate(const void* params, const void* context, void* diagnostics) noexcept {
  auto& out = *static_cast<std::vector<Diagnostic>*>(diagnostics);
  const auto& d = *static_cast<const Descriptor*>(params);
  try {
    T::validate(d, *static_cast<const PluginContext*>(context));
  } catch (const ConfigError& e) {
    out.push_back({Diagnostic::Severity::Error, e.where().line > 0 ? e.where() : d.where(), e.detail()});
  } catch (const std::exception& e) {
    out.push_back({Diagnostic::Severity::Error, d.where(), e.what()});
  } catch (...) {
    out.push_back({Diagnostic::Severity::Error, d.where(), "validate threw an unknown exception"});
  }
}

template <class T, class Base>
constexpr ssx_plugin_class pluginClass(std::uint32_t kind, const char* name) {
  static_assert(std::is_base_of_v<Base, T>, "SSX_DRIVER / SSX_SENSOR / SSX_EXTENSION: wrong base class");
  ssx_plugin_class c{kind,    name,      &pluginCreate<T, Base>, &pluginDestroy<Base>, "", nullptr, 0, nullptr,
                     sizeof(T), alignof(T), &pluginConstruct<T, Base>, &pluginDestruct<Base>};
  if constexpr (requires { T::kDoc; }) c.doc = T::kDoc;
  if constexpr (requires { T::kParameters; }) {
    c.params = std::data(T::kParameters);  // a C array, or a std::array (ssx::param::join)
    c.param_count = static_cast<std::uint32_t>(std::size(T::kParameters));
  }
  if constexpr (requires(const Descriptor& d, const PluginContext& ctx) { T::validate(d, ctx); })
    c.validate = &pluginValidate<T>;
  return c;
}

}  // namespace ssx::detail

/// A manifest entry (for SSX_PLUGIN) for driver class `Type`, named `name` in scenes.
#define SSX_DRIVER(Type, name) ::ssx::detail::pluginClass<Type, ::ssx::Driver>(SSX_PLUGIN_DRIVER, name)
/// A manifest entry for sensor class `Type`, named `name` in scenes.
#define SSX_SENSOR(Type, name) ::ssx::detail::pluginClass<Type, ::ssx::Sensor>(SSX_PLUGIN_SENSOR, name)
/// A manifest entry for extension class `Type`, named `name` in scenes.
#define SSX_EXTENSION(Type, name) \
  ::ssx::detail::pluginClass<Type, ::ssx::SimulationExtension>(SSX_PLUGIN_EXTENSION, name)

/// Writes the manifest of this plugin library from a list of SSX_DRIVER / SSX_SENSOR /
/// SSX_EXTENSION entries. Use once per library, at namespace scope.
#define SSX_PLUGIN(...)                                                                                  \
  namespace {                                                                                            \
  constexpr ssx_plugin_class ssx_plugin_classes_[] = {__VA_ARGS__};                                      \
  }                                                                                                      \
  extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1;    \
  extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1 = { \
      SSX_PLUGIN_ABI_VERSION,                                                                            \
      static_cast<std::uint32_t>(sizeof(ssx_plugin_manifest)),                                           \
      static_cast<std::uint32_t>(sizeof(ssx_plugin_class)),                                              \
      static_cast<std::uint32_t>(sizeof(ssx_plugin_classes_) / sizeof(ssx_plugin_classes_[0])),          \
      SSX_PLUGIN_BUILD_TAG,                                                                              \
      ssx_plugin_classes_}
