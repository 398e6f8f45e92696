#pragma once
// The exact state of a run as bytes, for checkpoint and restart (floedem run --resume).
//
// Each part of a run that carries state from one step to the next (the engine, the towing
// monitor, the collision tracker, the contact loads, the driver's running figures) writes it
// with a StateWriter and reads it back, in the same order, with a StateReader. Values are
// copied as their bytes: a restored run continues to the bit. Each part opens with a tag,
// so that a reader that does not match its writer fails at once, naming the part, instead of
// reading garbage.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace floedem {

/// The checkpoint cannot be read back (bad checksum, another layout, another scene).
class StateError : public std::runtime_error {
 public:
  explicit StateError(const std::string& m) : std::runtime_error(m) {}
};

class StateWriter {
 public:
  /// Starts a part: its name is checked on reading.
  void tag(const char* part) {
    const std::string s(part);
    value(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof v);
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    value(static_cast<std::uint64_t>(v.size()));
    raw(v.data(), v.size() * sizeof(T));
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }
  std::size_t size() const { return bytes_.size(); }
  /// Drops what was written after the first `size` bytes.
  void truncate(std::size_t size) { bytes_.resize(std::min(size, bytes_.size())); }
  void clear() { bytes_.clear(); }

 private:
  void raw(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    bytes_.insert(bytes_.end(), b, b + n);
  }
  std::vector<std::uint8_t> bytes_;
};

class StateReader {
 public:
  StateReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  void tag(const char* part) {
    const std::string want(part);
    const auto n = value<std::uint32_t>();
    if (n != want.size() || left() < n || std::memcmp(data_ + at_, want.data(), n) != 0)
      throw StateError("checkpoint: expected the state of '" + want + "' here (written by another layout?)");
    at_ += n;
  }
  template <class T>
  T value() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    raw(&v, sizeof v);
    return v;
  }
  template <class T>
  void value(T& v) {
    v = value<T>();
  }
  template <class T>
  void vector(std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = value<std::uint64_t>();
    if (n > left() / std::max<std::size_t>(sizeof(T), 1)) throw StateError("checkpoint: truncated");
    v.resize(static_cast<std::size_t>(n));
    raw(v.data(), v.size() * sizeof(T));
  }
  /// A vector that must have `n` entries (one per body, per part): a mismatch means another scene.
  template <class T>
  void vector(std::vector<T>& v, std::size_t n, const char* what) {
    vector(v);
    if (v.size() != n)
      throw StateError(std::string("checkpoint: ") + what + " has " + std::to_string(v.size()) + " entries, the scene " +
                       std::to_string(n));
  }
  std::size_t left() const { return size_ - at_; }

 private:
  void raw(void* p, std::size_t n) {
    if (left() < n) throw StateError("checkpoint: truncated");
    if (n > 0) std::memcpy(p, data_ + at_, n);
    at_ += n;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

/// FNV-1a, 64 bits: tells a checkpoint written whole from one cut short by a kill, and an input
/// file from one changed since a run read it. `h`: the hash so far, to go on block by block.
/// FNV-1a's offset basis: the hash of no bytes, where a hash block by block starts.
inline constexpr std::uint64_t kChecksumStart = 14695981039346656037ull;
inline std::uint64_t state_checksum(const std::uint8_t* p, std::size_t n, std::uint64_t h = kChecksumStart) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace floedem
