// Placing elements read into the model: a swarm's size against the memory.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a swarm that cannot fit in memory is an error at its line, before anything is made", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="box" file="box.xml"/>
    <swarm type="box" count="30000" name="a{i}"/>
    <swarm type="box" count="5000" name="b{i}"/>
  </scene>)";
  SceneOptions options;
  options.max_memory_bytes = std::uintmax_t{100} << 20;  // 30,000 boxes: about 88 MiB, estimated
  CHECK_NOTHROW(parseSceneString(xml.substr(0, xml.find("<swarm type=\"box\" count=\"5000\"")) + "</scene>", "m.xml",
                                 test::kArtifacts, options));
  try {
    (void)parseSceneString(xml, "m.xml", test::kArtifacts, options);
    FAIL("parsed");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("m.xml:4: error: <swarm>: 5000 members of 'box' need about") &&
                             Contains("with the artifacts before them), more than the memory allowed (0.0977 GiB): "
                                      "make 'count' smaller"));
  }
  // the machine's own memory by default: ten million boxes (the largest count) exceed any this runs on
  if (static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE)) < 28.0 * (1 << 30))
    CHECK_THROWS_WITH(parseSceneString(R"(<scene><type name="box" file="box.xml"/>
      <swarm type="box" count="10000000" name="b{i}"/></scene>)", "m.xml", test::kArtifacts, {}),
                      Contains("more than this machine's memory"));
}
