#pragma once
/// @file
/// StateWriter and StateReader: how the environment, the engines and plugins put what determines
/// the future into a saved world state (Environment::saveState) and take it back out
/// (Environment::restoreState). Values are written bit for bit (doubles included), so a restored
/// run continues bitwise identically.
///
/// A plugin whose behaviour depends on anything that changes while it runs (integrators,
/// filters, motor speeds, the last measurement it got, its own measurement buffer) overrides
/// `saveState` and `loadState` and writes and reads those values in the same order. Its random
/// stream is saved by the environment. What it computes once in `configure` from its parameters
/// is not state: a restore always happens in an environment configured from the same scene.

#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace ssx {

/// A saved state that cannot be restored: truncated, corrupted, from another scene or version.
class SSX_EXPORT StateError : public Error {
 public:
  using Error::Error;
};

/// Appends values to a byte buffer.
///
/// Made on a vector alone, each value is appended to it at once. Environment::saveState makes it
/// with a start offset instead: it then writes over what the vector already holds from there on
/// (a buffer kept from the last saved state: no allocation, no page faults), grows it only when
/// full, and trims it to what was written in finish() or its destructor. Until then the vector may
/// be longer than size(); the bytes past size() are not part of the state.
class StateWriter {
 public:
  /// A writer appending to `out`, which must outlive it.
  explicit StateWriter(std::vector<std::byte>& out) : out_(&out) {}
  /// A writer writing over `out` from byte `from` on (at most its size; the bytes before are
  /// kept), trimming it to what was written when finished. `out` must outlive it.
  StateWriter(std::vector<std::byte>& out, std::size_t from) : out_(&out), over_(true) {
    if (from > out.size()) out.resize(from);
    at_ = out.data() + from;
    room_ = out.size() - from;
  }
  StateWriter(const StateWriter&) = delete;
  StateWriter& operator=(const StateWriter&) = delete;
  ~StateWriter() { finish(); }

  /// Appends `size` raw bytes.
  void bytes(const void* data, std::size_t size) {
    if (size <= room_) {  // (a constant size inlines to a move)
      std::memcpy(at_, data, size);
      at_ += size;
      room_ -= size;
      return;
    }
    grow(data, size);
  }
  /// A trivially copyable value (numbers, enums, bools, arrays and structs of them).
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void write(const T& value) {
    bytes(&value, sizeof value);
  }
  /// A vector: x, y, z as doubles.
  void write(const Vec3& v) { bytes(v.data(), 3 * sizeof(double)); }
  /// A quaternion: x, y, z, w as doubles.
  void write(const Quat& q) { bytes(q.coeffs().data(), 4 * sizeof(double)); }
  /// A pose: its position, then its orientation.
  void write(const Pose& p) {
    write(p.position);
    write(p.orientation);
  }
  /// A text: its length (64 bits), then its bytes.
  void write(const std::string& s) {
    write(static_cast<std::uint64_t>(s.size()));
    bytes(s.data(), s.size());
  }
  /// A vector: its size, then each element as `write` writes it.
  template <class T>
  void write(const std::vector<T>& v) {
    write(static_cast<std::uint64_t>(v.size()));
    for (const T& x : v) write(x);
  }

  /// Bytes in the buffer so far (what was there before included).
  std::size_t size() const noexcept { return out_->size() - room_; }
  /// The buffer written to (past size(), bytes not written yet while writing over a buffer).
  std::vector<std::byte>& buffer() noexcept { return *out_; }
  /// Trims the buffer to size() (a writer writing over one; nothing for one appending). Nothing
  /// may be written after.
  void finish() noexcept {
    if (!over_) return;
    out_->resize(size());  // (shrinking: no allocation)
    room_ = 0;
    over_ = false;
  }

 private:
  void grow(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::byte*>(data);
    if (!over_) {
      out_->insert(out_->end(), p, p + size);
      return;
    }
    const std::size_t written = this->size();
    out_->resize(std::max(2 * out_->size(), written + size));
    at_ = out_->data() + written;
    room_ = out_->size() - written;
    bytes(data, size);
  }

  std::vector<std::byte>* out_;
  std::byte* at_ = nullptr;  // writing over: where the next byte goes
  std::size_t room_ = 0;     // ... and how many fit before the vector's end
  bool over_ = false;
};

/// Reads values back in the order they were written; throws StateError when the data ends early.
class StateReader {
 public:
  StateReader() = default;
  /// A reader of `data` (which must outlive it); `what` names the data in error messages.
  explicit StateReader(std::span<const std::byte> data, std::string what = "saved state")
      : data_(data), what_(std::move(what)) {}

  /// Reads `size` raw bytes into `out`; throws StateError when fewer are left.
  void bytes(void* out, std::size_t size) {
    if (size > remaining())
      throw StateError(what_ + " ends early: " + std::to_string(size) + " more bytes wanted, " +
                       std::to_string(remaining()) + " left (truncated, or saved by another version)");
    std::memcpy(out, data_.data() + at_, size);
    at_ += size;
  }
  /// A trivially copyable value, as StateWriter::write wrote it.
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void read(T& value) {
    bytes(&value, sizeof value);
  }
  /// A flag: a byte that is 0 or 1 (anything else is a corrupted state, not a bool).
  void read(bool& value) {
    unsigned char byte = 0;
    bytes(&byte, 1);
    if (byte > 1) throw StateError(what_ + ": a flag reads " + std::to_string(byte) + ", not 0 or 1 (corrupted)");
    value = byte == 1;
  }
  /// A vector: x, y, z as doubles.
  void read(Vec3& v) { bytes(v.data(), 3 * sizeof(double)); }
  /// A quaternion: x, y, z, w as doubles.
  void read(Quat& q) { bytes(q.coeffs().data(), 4 * sizeof(double)); }
  /// A pose: its position, then its orientation.
  void read(Pose& p) {
    read(p.position);
    read(p.orientation);
  }
  /// A text: its length, then its bytes (a length beyond the data is StateError).
  void read(std::string& s) {
    s.resize(count(1));
    bytes(s.data(), s.size());
  }
  /// A vector: its size, then each element as `read` reads it.
  template <class T>
  void read(std::vector<T>& v) {
    v.resize(count(1));
    for (T& x : v) read(x);
  }
  /// A value of type T.
  template <class T>
  T get() {
    T value{};
    read(value);
    return value;
  }
  /// An element count that cannot exceed what is left (each element at least `min_bytes`).
  std::size_t count(std::size_t min_bytes) {
    const auto n = get<std::uint64_t>();
    if (min_bytes > 0 && n > remaining() / min_bytes)
      throw StateError(what_ + ": a count of " + std::to_string(n) + " is more than the data holds (corrupted)");
    return static_cast<std::size_t>(n);
  }
  /// The next `size` bytes as a reader of their own (a length-prefixed block).
  StateReader block(std::size_t size, std::string what) {
    if (size > remaining()) throw StateError(what_ + " ends early inside " + what + " (truncated)");
    StateReader r(data_.subspan(at_, size), std::move(what));
    at_ += size;
    return r;
  }

  /// Bytes not read yet.
  std::size_t remaining() const noexcept { return data_.size() - at_; }
  /// Whether every byte was read.
  bool done() const noexcept { return at_ == data_.size(); }
  /// What the data is called in messages.
  const std::string& what() const noexcept { return what_; }

 private:
  std::span<const std::byte> data_;
  std::size_t at_ = 0;
  std::string what_;
};

}  // namespace ssx
