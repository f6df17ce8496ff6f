// Placing elements: what a <swarm> or <artifact> changes of its type's plugins.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a placing element's period overrides the type's plugin period and is no parameter", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="q" file="mk_quad_formation.xml"/>
    <swarm type="q" count="2" name="q{i}" spacing="2"><sensor index="2" period="3"/><driver period="2"/></swarm>
    <artifact name="plain" type="q" xyz="0 5 0"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "memory.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
  const Artifact& q = *scene.environment->findArtifact("q1");
  CHECK(q.sensor(2).periodSteps() == 3);  // the type says 10
  CHECK(q.sensor(0).periodSteps() == 1);
  CHECK(q.driver()->periodSteps() == 2);
  CHECK(scene.environment->findArtifact("plain")->sensor(2).periodSteps() == 10);
  for (const auto& w : scene.warnings) CHECK_THAT(w.message, !Catch::Contains("period"));
  std::vector<std::string> log;  // unread plugin parameters are reported at start
  scene.environment->setLogSink([&](LogLevel, std::string_view m) { log.emplace_back(m); });
  scene.environment->start();
  for (const auto& m : log) CHECK_THAT(m, !Catch::Contains("period"));
}

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
