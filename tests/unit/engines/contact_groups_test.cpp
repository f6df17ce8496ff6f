// The engines' shared contact groups (engines/contact_groups.hpp): bodies that touch end in one
// group under the root the engine picks, only touched bodies are visited, and clear() forgets all.
#include "engines/contact_groups.hpp"

#include <catch2/catch.hpp>

using ssx::detail::ContactGroups;

TEST_CASE("contact groups: touching bodies share a root, the lowest unless the engine picks", "[engines]") {
  ContactGroups g;
  g.resize(8);
  g.unite(5, 3);
  g.unite(3, 6);
  g.unite(1, 2);
  CHECK(g.rootOf(6) == 3);
  CHECK(g.find(5) == 3);
  CHECK(g.rootOf(2) == 1);
  CHECK_FALSE(g.grouped(0));
  CHECK_FALSE(g.grouped(7));
  CHECK(g.touched() == std::vector<int>{5, 3, 6, 1, 2});  // first touched first
  g.unite(6, 2);
  CHECK(g.rootOf(5) == 1);
  CHECK(g.rootOf(2) == 1);
  g.clear();
  for (int i = 0; i < 8; ++i) CHECK_FALSE(g.grouped(i));
  CHECK(g.touched().empty());
  // the engine's choice of root (ODE: a pinned body's group keeps its root)
  g.unite(1, 4, [](int ra, int rb) { return ra == 4 || rb == 4 ? 4 : (ra < rb ? ra : rb); });
  CHECK(g.rootOf(1) == 4);
  // a body alone is a group of its own once found
  CHECK(g.find(7) == 7);
  CHECK(g.grouped(7));
}
