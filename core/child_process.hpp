#pragma once
// Work that may crash or run for long (CGAL's corefinement and tetrahedral meshing) in a forked
// child process: a crash there costs only that step, and the parent keeps listening to the user
// while it waits — a progress line, and a stop (Ctrl-C, SIGTERM) that ends the child at once.
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace diefill {

struct ChildWait {
  std::function<bool()> stop;                   // polled every second: true ends the child
  std::function<void(double seconds)> waiting;  // called every `report_every_s` of waiting
  double report_every_s = 30.0;
};

enum class ChildOutcome { done, failed, stopped };

struct ChildResult {
  ChildOutcome outcome = ChildOutcome::failed;
  std::string bytes;  // what `work` returned, when done
  int status = 0;     // waitpid's status
};

// Runs `work` in a child process (in this one where fork fails) and returns the bytes it
// returned. `failed`: the child crashed, threw or could not send them; `stopped`: `wait.stop`
// asked for it. The child takes the default action of Ctrl-C, SIGTERM and SIGUSR1.
ChildResult run_in_child(const std::function<std::string()>& work, const ChildWait& wait = {});

// Plain values and arrays of them, packed into the child's bytes and read back in order.
class ByteWriter {
 public:
  template <class T>
  ByteWriter& put(const T& value) {
    static_assert(std::is_standard_layout_v<T> && std::is_trivially_destructible_v<T>);  // Eigen vectors too
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
    return *this;
  }
  template <class T>
  ByteWriter& put(const std::vector<T>& values) {
    static_assert(std::is_standard_layout_v<T> && std::is_trivially_destructible_v<T>);  // Eigen vectors too
    put(std::uint64_t(values.size()));
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    return *this;
  }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

// Reads what ByteWriter wrote; `ok()` turns false (and stays) at the first read past the end.
class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  template <class T>
  void get(T& value) {
    static_assert(std::is_standard_layout_v<T> && std::is_trivially_destructible_v<T>);  // Eigen vectors too
    if (!take(&value, sizeof value)) value = T{};
  }
  template <class T>
  void get(std::vector<T>& values) {
    std::uint64_t n = 0;
    get(n);
    if (!ok_ || n > (bytes_.size() - at_) / sizeof(T)) {
      ok_ = false;
      values.clear();
      return;
    }
    values.resize(n);
    take(values.data(), n * sizeof(T));
  }
  bool ok() const { return ok_ && at_ == bytes_.size(); }

 private:
  bool take(void* out, std::size_t n) {
    if (!ok_ || bytes_.size() - at_ < n) return ok_ = false;
    std::memcpy(out, bytes_.data() + at_, n);
    at_ += n;
    return true;
  }
  const std::string& bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

}  // namespace diefill
