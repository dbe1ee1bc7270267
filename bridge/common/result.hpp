#pragma once
// Result<T>: a value or an std::error_code. std::expected would do, but it needs
// C++23 with GCC and is unusable with clang 14 (used for fuzzing) on this libstdc++.
#include <cassert>
#include <optional>
#include <system_error>
#include <type_traits>
#include <utility>

#include "bridge/common/error.hpp"

namespace dnbridge {

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) noexcept(std::is_nothrow_move_constructible_v<T>)  // NOLINT(implicit)
      : value_(std::move(value)) {}
  Result(std::error_code error) noexcept : error_(error) {  // NOLINT(implicit)
    assert(error_);
  }
  Result(Errc error) noexcept : Result(make_error_code(error)) {}  // NOLINT(implicit)

  bool ok() const noexcept { return value_.has_value(); }
  explicit operator bool() const noexcept { return ok(); }
  const std::error_code& error() const noexcept { return error_; }

  T& value() & noexcept {
    assert(ok());
    return *value_;
  }
  const T& value() const& noexcept {
    assert(ok());
    return *value_;
  }
  T&& value() && noexcept {
    assert(ok());
    return std::move(*value_);
  }
  T& operator*() & noexcept { return value(); }
  const T& operator*() const& noexcept { return value(); }
  T* operator->() noexcept { return &value(); }
  const T* operator->() const noexcept { return &value(); }
  template <class U>
  T value_or(U&& fallback) const& {
    return ok() ? *value_ : T(std::forward<U>(fallback));
  }

 private:
  std::optional<T> value_;
  std::error_code error_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() noexcept = default;
  Result(std::error_code error) noexcept : error_(error) {}        // NOLINT(implicit)
  Result(Errc error) noexcept : error_(make_error_code(error)) {}  // NOLINT(implicit)

  bool ok() const noexcept { return !error_; }
  explicit operator bool() const noexcept { return ok(); }
  const std::error_code& error() const noexcept { return error_; }

 private:
  std::error_code error_;
};

using Status = Result<void>;

}  // namespace dnbridge
