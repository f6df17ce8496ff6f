#pragma once
/// @file
/// Artifact: anything placed in a scene. Physic and render node trees, at most one driver, any
/// number of sensors.

#include <ssx/descriptor.hpp>
#include <ssx/export.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/plugin.hpp>
#include <ssx/render.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace ssx {

class Environment;
namespace detail {
struct World;
}

/// An artifact. Created by `Environment::addArtifact`; owned by the environment.
/// Node trees, drivers and sensors are added before the environment starts.
///
/// A handle: what changes while the world runs (its plugins' slots, subscriptions, bodies) lives
/// in the environment's world state, indexed by `index()`.
class SSX_EXPORT Artifact {
 public:
  /// Made by Environment::addArtifact (the world is the core's and cannot be named outside it).
  Artifact(detail::World& world, std::string name, std::size_t index, const Pose& placement);
  Artifact(const Artifact&) = delete;
  Artifact& operator=(const Artifact&) = delete;
  ~Artifact();

  /// The artifact's name, unique in its environment (the scene's `name`, or a swarm's member name).
  const std::string& name() const noexcept { return name_; }
  /// Position in the environment's artifact list; streams and orders derive from it.
  std::size_t index() const noexcept { return index_; }
  /// Whether it is in the world: false once Environment::despawn took it out (or the scene said
  /// present="false"), until Environment::spawn puts it back.
  bool present() const noexcept;
  /// The environment, read-only: what may change it (subscriptions, neighbour queries, camera
  /// requests) is reached from a plugin's configure (PluginSetup) or by the embedding program.
  const Environment& environment() const noexcept { return *env_; }
  /// The pose the artifact was placed at; root nodes are posed relative to it.
  const Pose& placement() const noexcept { return placement_; }

  // --- setup (before the environment starts) ---------------------------------------------

  /// Adds a physic node tree (checked with validatePhysicTree) and returns its root node.
  PhysicNode& addPhysicRoot(PhysicNodeSpec spec);
  /// The same, for a tree shared by many artifacts (a swarm's type): it is not copied.
  PhysicNode& addPhysicRoot(std::shared_ptr<const PhysicNodeSpec> spec);
  /// Adds a render node tree.
  void addRenderRoot(RenderNodeSpec spec);
  /// The same, for a tree shared by many artifacts (a swarm's type): it is not copied.
  void addRenderRoot(std::shared_ptr<const RenderNodeSpec> spec);
  /// Sets the driver. `class_name` names it in messages; `period_steps` >= 1.
  Driver& setDriver(std::unique_ptr<Driver> driver, Descriptor params = {}, std::int64_t period_steps = 1,
                    std::string class_name = {});
  /// Adds a sensor; returns it. Sensor i has plugin index i + 1 (the driver has 0).
  Sensor& addSensor(std::unique_ptr<Sensor> sensor, Descriptor params = {}, std::int64_t period_steps = 1,
                    std::string class_name = {});
  /// Same, for instances owned elsewhere (by the environment's ClassLoader); they must outlive
  /// the environment's run.
  Driver& setDriver(Driver& driver, Descriptor params, std::int64_t period_steps, std::string class_name);
  /// Adds a sensor owned elsewhere (by the environment's ClassLoader); it must outlive the
  /// environment's run. Returns it.
  Sensor& addSensor(Sensor& sensor, Descriptor params, std::int64_t period_steps, std::string class_name);

  // --- access -------------------------------------------------------------------------------
  // Through a const Artifact (what plugins see of other artifacts, and sensors of their own)
  // nodes, driver and sensors are const: reading the state, not writing commands.

  /// The driver, or nullptr when the artifact has none (a passive body).
  Driver* driver() noexcept;
  /// @copydoc driver()
  const Driver* driver() const noexcept;
  /// How many sensors the artifact has.
  std::size_t sensorCount() const noexcept;
  /// Sensor i, in the order added (0 <= i < sensorCount(); std::out_of_range otherwise).
  Sensor& sensor(std::size_t i);
  /// @copydoc sensor(std::size_t)
  const Sensor& sensor(std::size_t i) const;
  /// The parameters the driver is (or will be) configured with.
  const Descriptor& driverParameters() const noexcept;
  /// The parameters sensor i is (or will be) configured with.
  const Descriptor& sensorParameters(std::size_t i) const;
  /// The first sensor of type T, or nullptr.
  template <class T>
  T* findSensor() {
    for (std::size_t i = 0; i < sensorCount(); ++i)
      if (auto* t = dynamic_cast<T*>(&sensor(i))) return t;
    return nullptr;
  }
  /// @copydoc findSensor()
  template <class T>
  const T* findSensor() const {
    for (std::size_t i = 0; i < sensorCount(); ++i)
      if (auto* t = dynamic_cast<const T*>(&sensor(i))) return t;
    return nullptr;
  }

  /// How many physic node trees the artifact has.
  std::size_t rootCount() const noexcept { return roots_.size(); }
  /// The root node of tree i, in the order added (std::out_of_range when there is none).
  PhysicNode& root(std::size_t i = 0) { return i == 0 && first_root_ != nullptr ? *first_root_ : *roots_.at(i); }
  /// @copydoc root(std::size_t)
  const PhysicNode& root(std::size_t i = 0) const {
    return i == 0 && first_root_ != nullptr ? *first_root_ : *roots_.at(i);
  }
  /// Node by name, searching every tree; nullptr if none.
  PhysicNode* node(std::string_view name);
  /// @copydoc node(std::string_view)
  const PhysicNode* node(std::string_view name) const;
  /// The node a plugin parameter names (`key`, default "node"), or the first root when the parameter
  /// is absent or empty; throws the parameter's ConfigError when there is no such node.
  PhysicNode& nodeFromParameter(const Descriptor& params, std::string_view key = "node");
  /// @copydoc nodeFromParameter(const Descriptor&, std::string_view)
  const PhysicNode& nodeFromParameter(const Descriptor& params, std::string_view key = "node") const;
  /// Every node of every tree, trees in order (node i of nodeCount()).
  std::size_t nodeCount() const noexcept { return nodes_.size(); }
  /// Node i of every tree's nodes, parents before children (std::out_of_range past nodeCount()).
  PhysicNode& nodeAt(std::size_t i) { return *nodes_.at(i); }
  /// @copydoc nodeAt(std::size_t)
  const PhysicNode& nodeAt(std::size_t i) const { return *nodes_.at(i); }
  /// The render node trees, in the order added (trees of a swarm's type are shared by its members).
  const std::vector<std::shared_ptr<const RenderNodeSpec>>& renderRoots() const noexcept { return render_roots_; }

  /// State of the first root node (world frame). Requires a physic root.
  BodyState state() const { return root().state(); }
  /// Pose of the first root node (world frame). Requires a physic root.
  Pose pose() const { return root().pose(); }

 private:
  void buildNodes(PhysicNode* parent, const PhysicNodeSpec& spec);
  void requireSetup(const char* what) const;
  Plugin& attach(Plugin& plugin, std::uint32_t plugin_index, std::int64_t period_steps, std::string class_name,
                 const Descriptor& params);

  detail::World* world_;
  // root 0, the node plugins read every step, held here too: root() then reads no other block
  PhysicNode* first_root_ = nullptr;
  const Environment* env_;
  std::string name_;
  std::size_t index_;
  Pose placement_;
  std::vector<std::shared_ptr<const PhysicNodeSpec>> root_specs_;
  std::vector<PhysicNode*> nodes_;  // every node, trees in order (held by the world)
  std::vector<PhysicNode*> roots_;
  std::vector<std::shared_ptr<const RenderNodeSpec>> render_roots_;
};

}  // namespace ssx
