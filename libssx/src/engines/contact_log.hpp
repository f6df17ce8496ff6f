#pragma once
// The contacts of a step as PhysicEngine::contacts lists them: an engine adds every contact point
// with the normal impulse its solver gave it, and the log merges them into one record per pair of
// bodies (or a body and the static world), in a fixed order: the same on every thread count.
#include <ssx/physic_engine.hpp>

#include <algorithm>
#include <utility>
#include <vector>

namespace ssx::detail {

class ContactLog {
 public:
  bool on() const noexcept { return on_; }
  /// Starts or stops keeping contacts; either way the list is emptied.
  void setOn(bool on) {
    on_ = on;
    begin();
  }
  /// A new step: the points of the last one are dropped.
  void begin() {
    points_.clear();
    pairs_.clear();
  }
  /// A contact point between bodies `a` and `b` (-1: a static shape of addStatic's group
  /// `static_group`), `normal` from b towards a.
  void add(int a, int b, int static_group, const Vec3& position, Vec3 normal, double depth, double impulse) {
    if (a < 0 || (b >= 0 && b < a)) {
      std::swap(a, b);
      normal = -normal;
    }
    points_.push_back({{a, b, position, normal, impulse, b < 0 ? static_group : -1}, depth});
  }
  /// Merges the points into pairs: ascending body_a, then body_b (-1 first), then the static
  /// group; the deepest point (the first of equals, in the engine's order) stands for the pair;
  /// impulses add up.
  void finish() {
    std::stable_sort(points_.begin(), points_.end(), [](const Point& x, const Point& y) {
      const EngineContact &p = x.contact, &q = y.contact;
      if (p.body_a != q.body_a) return p.body_a < q.body_a;
      return p.body_b != q.body_b ? p.body_b < q.body_b : p.static_group < q.static_group;
    });
    pairs_.clear();
    double deepest = 0;
    for (const Point& p : points_) {
      if (pairs_.empty() || pairs_.back().body_a != p.contact.body_a || pairs_.back().body_b != p.contact.body_b ||
          pairs_.back().static_group != p.contact.static_group) {
        pairs_.push_back(p.contact);
        deepest = p.depth;
        continue;
      }
      EngineContact& pair = pairs_.back();
      pair.impulse += p.contact.impulse;
      if (p.depth > deepest) {
        deepest = p.depth;
        pair.position = p.contact.position;
        pair.normal = p.contact.normal;
      }
    }
  }
  const std::vector<EngineContact>& pairs() const noexcept { return pairs_; }

 private:
  struct Point {
    EngineContact contact;
    double depth = 0;
  };
  bool on_ = false;
  std::vector<Point> points_;
  std::vector<EngineContact> pairs_;
};

}  // namespace ssx::detail
