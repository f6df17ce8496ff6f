#pragma once
// Bodies that touch, grouped: a union-find over body indices, shared by the engines (ODE moves a
// group into one world, Bullet solves it as one island). Only the bodies touched this substep are
// visited, in the order first touched, and cleared after, so its cost follows the contacts, not
// the bodies.

#include <cstddef>
#include <vector>

namespace ssx::detail {

class ContactGroups {
 public:
  /// Room for `bodies` bodies, every one in no group.
  void resize(std::size_t bodies) { group_.assign(bodies, -1); }
  std::size_t size() const noexcept { return group_.size(); }
  void reserve(std::size_t bodies) { touched_.reserve(bodies); }

  /// The root of x's group; x becomes a group of its own (and touched) if it was in none.
  int find(int x) {
    if (group_[static_cast<std::size_t>(x)] < 0) {
      group_[static_cast<std::size_t>(x)] = x;
      touched_.push_back(x);
    }
    while (group_[static_cast<std::size_t>(x)] != x) {  // path halving
      const int up = group_[static_cast<std::size_t>(group_[static_cast<std::size_t>(x)])];
      group_[static_cast<std::size_t>(x)] = up;
      x = up;
    }
    return x;
  }
  /// The root of x's group without changing anything (x must be in one).
  int rootOf(int x) const {
    while (group_[static_cast<std::size_t>(x)] != x) x = group_[static_cast<std::size_t>(x)];
    return x;
  }
  /// Joins the groups of a and b; `pick(ra, rb)` says which root stays the root.
  template <class Pick>
  void unite(int a, int b, Pick pick) {
    const int ra = find(a);
    const int rb = find(b);
    if (ra == rb) return;
    const int root = pick(ra, rb);
    group_[static_cast<std::size_t>(root == ra ? rb : ra)] = root;
  }
  /// Joins them, the lower root staying the root.
  void unite(int a, int b) {
    unite(a, b, [](int ra, int rb) { return ra < rb ? ra : rb; });
  }
  /// Whether x is in a group this substep.
  bool grouped(int x) const { return group_[static_cast<std::size_t>(x)] >= 0; }
  /// The bodies in a group this substep, first touched first.
  const std::vector<int>& touched() const noexcept { return touched_; }
  /// Every body back to no group.
  void clear() {
    for (const int i : touched_) group_[static_cast<std::size_t>(i)] = -1;
    touched_.clear();
  }

 private:
  std::vector<int> group_;    // per body: its parent in the union-find, -1 in no group
  std::vector<int> touched_;  // the bodies in a group, first touched first
};

}  // namespace ssx::detail
