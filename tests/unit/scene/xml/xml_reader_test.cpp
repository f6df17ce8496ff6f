// XML text and files into Descriptor trees (ssx::parseXml, ssx::readXmlFile): lines, errors.
#include <ssx/descriptor.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

using namespace ssx;

TEST_CASE("XML becomes a Descriptor tree, every element and attribute with its line", "[xml]") {
  const Descriptor root = parseXml("<scene>\n  <a x=\"1\"\n     y=\"2\">\n    <b/>\n  </a>\n  <!-- c -->\n  <c/>\n</scene>",
                                   "mem.xml");
  CHECK(root.name() == "scene");
  CHECK(root.where().file == "mem.xml");
  CHECK(root.where().line == 1);
  REQUIRE(root.children().size() == 2);  // comments are no elements
  const Descriptor& a = root.children()[0];
  CHECK(a.where().line == 2);
  CHECK(a.find("x")->where.line == 2);
  CHECK(a.find("y")->where.line == 3);  // an attribute on a later line than its element
  CHECK(a.get<int>("y") == 2);
  CHECK(a.children()[0].name() == "b");
  CHECK(a.children()[0].where().line == 4);
  CHECK(root.children()[1].where().line == 7);
}

TEST_CASE("XML errors say where: a syntax error at its line, a file that cannot be read, nesting too deep", "[xml]") {
  CHECK_THROWS_WITH(parseXml("<scene>\n<a>\n</scene>", "bad.xml"), Catch::StartsWith("bad.xml:") && Catch::Contains("XML syntax"));
  try {
    (void)parseXml("<scene>\n<a>\n</scene>", "bad.xml");
  } catch (const ConfigError& e) {
    CHECK(e.where().line >= 2);
  }
  CHECK_THROWS_WITH(readXmlFile(std::filesystem::temp_directory_path() / "ssx_no_such_file.xml"),
                    Catch::Contains("ssx_no_such_file.xml"));
  std::string deep;
  for (int i = 0; i < 70; ++i) deep += "<e>";
  for (int i = 0; i < 70; ++i) deep += "</e>";
  CHECK_THROWS_WITH(parseXml(deep, "deep.xml"), Catch::Contains("nested more than 64 levels deep"));
}

TEST_CASE("lines are counted the same whether they end in LF, CRLF or a lone CR", "[xml]") {
  for (const char* eol : {"\n", "\r\n", "\r"}) {
    const std::string e = eol;
    const Descriptor root = parseXml("<scene>" + e + "<a/>" + e + e + "<b x=\"1\"/>" + e + "</scene>", "eol.xml");
    INFO("line end " << (e == "\n" ? "LF" : e == "\r\n" ? "CRLF" : "CR"));
    CHECK(root.children().at(0).where().line == 2);
    CHECK(root.children().at(1).where().line == 4);
    CHECK(root.children().at(1).find("x")->where.line == 4);
    try {
      (void)parseXml("<scene>" + e + e + "<a>" + e + "</scene>", "eol.xml");
      FAIL("parsed");
    } catch (const ConfigError& err) {
      CHECK(err.where().line >= 3);
    }
  }
}

TEST_CASE("an XML file is read as an input file: bounded, and regular", "[xml]") {
  CHECK_THROWS_WITH(readXmlFile("/dev/zero"), Catch::Contains("not a regular file"));
  const auto file = std::filesystem::temp_directory_path() / "ssx_xml_limit.xml";
  {
    std::ofstream out(file);
    out << "<scene>" << std::string(4096, ' ') << "</scene>";
  }
  CHECK(readXmlFile(file).name() == "scene");
  CHECK_THROWS_WITH(readXmlFile(file, 1024), Catch::Contains("larger than the limit on input files"));
  std::filesystem::remove(file);
}
