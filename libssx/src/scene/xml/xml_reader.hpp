#pragma once
// XML files to Descriptor trees, every element and attribute with its file and line.

#include <ssx/descriptor.hpp>

#include <filesystem>
#include <string>
#include <string_view>

// (ssx::parseXml and ssx::readXmlFile are public: ssx/descriptor.hpp)
