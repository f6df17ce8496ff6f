#include "scene/xml/xml_reader.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <vector>

namespace ssx::detail {

namespace {

// maps byte offsets to 1-based line numbers
class LineIndex {
 public:
  explicit LineIndex(std::string_view text) {
    // a line ends at LF, CRLF or a lone CR (old Mac files): each ends one line
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n' || (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n')))
        newlines_.push_back(i);
  }
  int line(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    const auto it = std::lower_bound(newlines_.begin(), newlines_.end(), static_cast<std::size_t>(offset));
    return static_cast<int>(it - newlines_.begin()) + 1;
  }

 private:
  std::vector<std::size_t> newlines_;
};

// offset of `name=` inside the start tag that begins at `tag`, or the tag's offset
std::ptrdiff_t attributeOffset(std::string_view text, std::ptrdiff_t tag, std::string_view name) {
  if (tag < 0 || static_cast<std::size_t>(tag) >= text.size()) return tag;
  const std::size_t end = text.find('>', static_cast<std::size_t>(tag));
  std::size_t pos = static_cast<std::size_t>(tag);
  while ((pos = text.find(name, pos + 1)) != std::string_view::npos && pos < end) {
    const bool space_before = std::isspace(static_cast<unsigned char>(text[pos - 1])) != 0;
    std::size_t after = pos + name.size();
    while (after < text.size() && std::isspace(static_cast<unsigned char>(text[after])) != 0) ++after;
    if (space_before && after < text.size() && text[after] == '=') return static_cast<std::ptrdiff_t>(pos);
  }
  return tag;
}

// deeper than any scene or artifact needs (a physic tree of a robot arm is a dozen levels); what
// reads the tree recursively can rely on it
constexpr int kMaxDepth = 64;

Descriptor convert(const pugi::xml_node& node, std::string_view text, const LineIndex& lines, const std::string& file,
                   int depth = 1) {
  const std::ptrdiff_t offset = node.offset_debug();
  if (depth > kMaxDepth)
    throw ConfigError({file, lines.line(offset)}, "<" + std::string(node.name()) + ">: elements are nested more than " +
                                                      std::to_string(kMaxDepth) + " levels deep");
  Descriptor d(node.name(), {file, lines.line(offset)});
  for (const auto& a : node.attributes()) {
    // (XML forbids it and pugixml keeps both: which one a reader took would be an accident)
    if (d.has(a.name()))
      throw ConfigError({file, lines.line(attributeOffset(text, offset, a.name()))},
                        "<" + std::string(node.name()) + ">: attribute '" + a.name() +
                            "' is given twice: keep one");
    d.set(a.name(), a.value(), {file, lines.line(attributeOffset(text, offset, a.name()))});
  }
  for (const auto& child : node.children())
    if (child.type() == pugi::node_element) d.addChild(convert(child, text, lines, file, depth + 1));
  return d;
}

}  // namespace

}  // namespace ssx::detail

namespace ssx {

using detail::convert;
using detail::LineIndex;

Descriptor parseXml(std::string_view text, const std::string& file) {
  pugi::xml_document doc;
  const pugi::xml_parse_result result =
      doc.load_buffer(text.data(), text.size(), pugi::parse_default | pugi::parse_declaration);
  const LineIndex lines(text);
  if (!result) throw ConfigError({file, lines.line(result.offset)}, std::string("XML syntax: ") + result.description());
  const pugi::xml_node root = doc.document_element();
  if (!root) throw ConfigError({file, 1}, "the file has no XML element");
  return convert(root, text, lines, file);
}

Descriptor readXmlFile(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  return parseXml(readInputFile(file, max_bytes), file.string());
}

}  // namespace ssx
