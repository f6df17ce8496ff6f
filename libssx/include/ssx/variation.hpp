#pragma once
/// @file
/// Physical constants that change between episodes: a learning environment's domain
/// randomisation (a thrust coefficient 4 % low, a heavier airframe, a noisier IMU, a breeze).
///
/// A plugin that lets some of its constants vary implements VariationInterface; the
/// Environment finds it among an artifact's plugins (Environment::vary), keeps every value set
/// in its saved state and sets them again on restore, so a plugin saves nothing of them itself.
/// A value is relative to what the plugin was configured with: each variable has a neutral
/// value (1 for a factor, 0 for an offset) at which the constant is the scene's again. What a
/// plugin's controller believes (a flight controller's mass, its thrust model) keeps the
/// scene's values, as a firmware deployed on a real robot would.
///
/// The artifact's bodies vary through two variables the Environment itself provides: `mass`
/// and `inertia`, factors on each body's mass and inertia as the scene gave them.
#include <ssx/export.hpp>

#include <cstddef>
#include <span>

namespace ssx {

/// One constant a plugin lets vary.
struct Variable {
  const char* name;  ///< as a scene would name its parameter: "thrust_coefficient"
  double neutral;    ///< the value at which the constant is the configured one: 1 (a factor) or 0 (an offset)
  double min;        ///< the smallest value allowed
  double max;        ///< the largest value allowed
  const char* doc;   ///< one line: what the value does, with its unit
};

/// Implemented by plugins whose constants may vary between steps (see the file comment).
class SSX_EXPORT VariationInterface {
 public:
  virtual ~VariationInterface();
  /// The constants this plugin lets vary: the same list, in the same order, for the plugin's life.
  virtual std::span<const Variable> variables() const = 0;
  /// Sets variables()[k] to `value` (within its min and max, checked by the caller) from the next
  /// step on. Called between steps only.
  virtual void vary(std::size_t k, double value) = 0;
};

}  // namespace ssx
