#include <ssx/descriptor.hpp>

#include <catch2/catch.hpp>

#include <locale>
#include <string>

using ssx::ConfigError;
using ssx::Descriptor;

TEST_CASE("descriptor parses typed attributes", "[descriptor]") {
  Descriptor d("driver", {"robot.xml", 12});
  d.set("kp", "2.5").set("count", "7").set("on", "true").set("name", "hover").set("target", "1 2.5 -3");
  CHECK(d.get<double>("kp") == 2.5);
  CHECK(d.get<int>("count") == 7);
  CHECK(d.get<std::int64_t>("count") == 7);
  CHECK(d.get<bool>("on"));
  CHECK(d.get<std::string>("name") == "hover");
  CHECK(d.get<ssx::Vec3>("target").isApprox(ssx::Vec3(1, 2.5, -3)));
  CHECK(d.get<double>("absent", 4.0) == 4.0);
}

TEST_CASE("descriptor errors carry file, line, element and attribute", "[descriptor]") {
  Descriptor d("driver", {"robot.xml", 12});
  d.set("kp", "fast", {"robot.xml", 14});
  d.set("count", "7.5");
  d.set("gain", "-1");
  try {
    (void)d.get<double>("kp");
    FAIL("no error");
  } catch (const ConfigError& e) {
    CHECK(std::string(e.what()) == "robot.xml:14: error: <driver>: attribute 'kp' must be a finite number, got 'fast'");
  }
  try {
    (void)d.get<int>("count");
    FAIL("no error");
  } catch (const ConfigError& e) {
    CHECK(std::string(e.what()).rfind("robot.xml:12: error: <driver>: attribute 'count' must be an integer", 0) == 0);
  }
  try {
    (void)d.get<double>("missing");
    FAIL("no error");
  } catch (const ConfigError& e) {
    CHECK(std::string(e.what()) == "robot.xml:12: error: <driver>: missing attribute 'missing'");
    CHECK(e.where().line == 12);
  }
  CHECK_THROWS_WITH(d.getPositive("gain", 1.0), Catch::Contains("must be positive"));
  CHECK_THROWS_AS(d.get<ssx::Vec3>("kp"), ConfigError);
  Descriptor n("x");
  n.set("v", "nan");
  CHECK_THROWS_AS(n.get<double>("v"), ConfigError);
}

TEST_CASE("descriptor reports attributes nobody read", "[descriptor]") {
  Descriptor d("sensor", {"a.xml", 3});
  d.set("rate", "100").set("typo_rate", "5");
  (void)d.get<double>("rate");
  const auto warnings = d.unusedAttributeWarnings();
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0] == "a.xml:3: warning: unknown attribute 'typo_rate' of <sensor>");
}

TEST_CASE("descriptor children keep document order", "[descriptor]") {
  Descriptor d("artifact");
  d.addChild(Descriptor("sensor")).set("i", 0);
  d.addChild(Descriptor("driver"));
  d.addChild(Descriptor("sensor")).set("i", 1);
  const auto sensors = d.childrenNamed("sensor");
  REQUIRE(sensors.size() == 2);
  CHECK(sensors[0]->get<int>("i") == 0);
  CHECK(sensors[1]->get<int>("i") == 1);
  CHECK(d.child("driver") != nullptr);
  CHECK(d.child("camera") == nullptr);
}

TEST_CASE("numbers written by set read back exactly", "[descriptor]") {
  Descriptor d("x");
  const double v = 0.1 + 0.2;
  d.set("v", v).set("vec", ssx::Vec3(1.0 / 3.0, -2e-9, 7.0));
  CHECK(d.get<double>("v") == v);
  CHECK(d.get<ssx::Vec3>("vec") == ssx::Vec3(1.0 / 3.0, -2e-9, 7.0));
}

TEST_CASE("numbers are read and written the same under a program's decimal-comma locale", "[descriptor]") {
  // an embedding program may set a global C++ locale whose decimal point is a comma; scene values
  // and the numbers Descriptor writes must not follow it
  struct Comma : std::numpunct<char> {
    char do_decimal_point() const override { return ','; }
  };
  const std::locale before = std::locale::global(std::locale(std::locale::classic(), new Comma));
  Descriptor d("x");
  d.set("a", 0.5).set("vec", ssx::Vec3(1.5, -2.25, 1e-3));
  d.set("b", std::string(" +2.5e-1 "));
  const std::string written = d.find("a")->value;
  const double a = d.get<double>("a"), b = d.get<double>("b");
  const ssx::Vec3 vec = d.get<ssx::Vec3>("vec");
  std::locale::global(before);
  CHECK(written == "0.5");
  CHECK(a == 0.5);
  CHECK(b == 0.25);
  CHECK(vec == ssx::Vec3(1.5, -2.25, 1e-3));
}

TEST_CASE("numbers out of the double range, hex and trailing text are no numbers", "[descriptor]") {
  Descriptor d("x");
  for (const char* bad : {"1e400", "-1e400", "nan", "inf", "0x10", "1.5m", "1,5", "", " "}) {
    d.set("v", std::string(bad));
    CHECK_THROWS_AS(d.get<double>("v"), ssx::ConfigError);
  }
  d.set("v", std::string("1e-400"));  // underflows to a denormal or 0: from_chars calls that out of range
  CHECK_THROWS_AS(d.get<double>("v"), ssx::ConfigError);
}
