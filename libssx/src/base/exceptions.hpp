#pragma once
// The message of an exception held in an exception_ptr, for errors that name where it happened
// ("copy 3: ...", "sensor 1 of 'cf': ...").
#include <exception>
#include <string>

namespace ssx::detail {

inline std::string describe(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& ex) {
    return ex.what();
  } catch (...) {
    return "unknown exception";
  }
}

}  // namespace ssx::detail
