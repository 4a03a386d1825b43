// SPDX-License-Identifier: MIT
// Cumulative writes that an executor can redirect: how live task bodies write a CW datum
// into a temporary when their reduction is lowered (paper section 3.2).
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <type_traits>

namespace tgraph {

/// How to make and combine temporaries of one datum's storage, so that an executor can
/// give a CW writer running on another thread its own zeroed copy and add it back later.
///
///   StateVec f;                                   // storage of datum "bar0.f"
///   Accumulator acc = make_accumulator(f);        // declared beside the datum
///   rec.task(k, obj, {{fd, AccessMode::CW}}, [&f] { accumulate(f) += g; });
struct Accumulator {
  void* target = nullptr;  ///< the storage; bodies pass this object to accumulate()
  /// A temporary of the target's shape, zeroed.
  std::function<std::shared_ptr<void>()> make_zero;
  /// target += temp, then temp = 0 (elementwise, in this order).
  std::function<void(void* target, void* temp)> add_and_clear;
};

namespace detail {
template <class T>
void set_zero(T& v) {
  if constexpr (std::is_arithmetic_v<T>) {
    v = T{};
  } else {
    v.setZero();  // Eigen vectors and matrices
  }
}
}  // namespace detail

/// An Accumulator for `storage`: an arithmetic value or an Eigen dense object (anything with
/// setZero() and +=). `storage` must outlive every step that uses it.
template <class T>
Accumulator make_accumulator(T& storage) {
  Accumulator a;
  a.target = &storage;
  a.make_zero = [&storage] {
    auto t = std::make_shared<T>(storage);
    detail::set_zero(*t);
    return std::shared_ptr<void>(t);
  };
  a.add_and_clear = [](void* target, void* temp) {
    T& tt = *static_cast<T*>(temp);
    *static_cast<T*>(target) += tt;
    detail::set_zero(tt);
  };
  return a;
}

/// One redirection in force on the calling thread: writes meant for `target` go to `temp`.
struct Redirect {
  const void* target = nullptr;
  void* temp = nullptr;
};

namespace detail {
/// The redirections of the task running on this thread (empty outside redirected tasks).
inline thread_local std::span<const Redirect> tl_redirects;
}  // namespace detail

/// Where a CW writer running now must add into `target`: `target` itself, unless the
/// executor redirected this task's cumulative write of it to a temporary. Costs one
/// thread-local read when nothing is redirected.
template <class T>
T& accumulate(T& target) {
  const std::span<const Redirect> r = detail::tl_redirects;
  if (r.empty()) [[likely]]
    return target;
  for (const Redirect& x : r)
    if (x.target == &target) return *static_cast<T*>(x.temp);
  return target;
}

/// Installs redirections for the scope of one task body on this thread.
class RedirectScope {
 public:
  explicit RedirectScope(std::span<const Redirect> r) : saved_(detail::tl_redirects) {
    detail::tl_redirects = r;
  }
  ~RedirectScope() { detail::tl_redirects = saved_; }
  RedirectScope(const RedirectScope&) = delete;
  RedirectScope& operator=(const RedirectScope&) = delete;

 private:
  std::span<const Redirect> saved_;
};

}  // namespace tgraph
