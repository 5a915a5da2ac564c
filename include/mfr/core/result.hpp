// Library errors are values: a Result<T> holds either a T or an Error whose message names the input
// that caused it. Programmer errors are checks (MFR_CHECK), never Results.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

namespace mfr {

struct Error {
  std::string message;
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}
  Result(Error error) : v_(std::move(error)) {}

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

/// Result of an operation that returns nothing on success.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { return error_; }

 private:
  Error error_;
  bool ok_ = true;
};

inline Error makeError(std::string message) {
  return Error{std::move(message)};
}

namespace detail {

/// A checked value as MFR_CHECK_EQ and its kin print it: numbers (floating point with 9
/// significant digits), enums as their number, bools, strings, pointers; "?" for anything else.
template <class T>
std::string checkValueText(const T& v) {
  char text[64];
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "true" : "false";
  } else if constexpr (std::is_floating_point_v<T>) {
    std::snprintf(text, sizeof text, "%.9g", static_cast<double>(v));
    return text;
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else if constexpr (std::is_enum_v<T>) {
    return std::to_string(static_cast<std::underlying_type_t<T>>(v));
  } else if constexpr (std::is_convertible_v<const T&, std::string_view>) {
    return std::string(std::string_view(v));
  } else if constexpr (std::is_pointer_v<T>) {
    std::snprintf(text, sizeof text, "%p", static_cast<const void*>(v));
    return text;
  } else {
    return "?";
  }
}

template <class A, class B>
[[noreturn]] void checkOpFailed(const char* file, int line, const char* expression, const A& a,
                                const B& b) {
  std::fprintf(stderr, "%s:%d: internal check failed: %s (%s vs. %s)\n", file, line, expression,
               checkValueText(a).c_str(), checkValueText(b).c_str());
  std::abort();
}

}  // namespace detail

}  // namespace mfr

/// Always-on check of a programmer invariant (not of user input).
#define MFR_CHECK(cond)                                                                      \
  do {                                                                                       \
    if (!(cond)) {                                                                           \
      std::fprintf(stderr, "%s:%d: internal check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                          \
    }                                                                                        \
  } while (0)

/// MFR_CHECK of one comparison that also prints both values, as
/// "file:line: internal check failed: a <= b (5 vs. 3)". Each operand is evaluated once.
#define MFR_CHECK_OP_(op, a, b)                                                         \
  do {                                                                                  \
    const auto& mfr_check_a_ = (a);                                                     \
    const auto& mfr_check_b_ = (b);                                                     \
    if (!(mfr_check_a_ op mfr_check_b_))                                                \
      ::mfr::detail::checkOpFailed(__FILE__, __LINE__, #a " " #op " " #b, mfr_check_a_, \
                                   mfr_check_b_);                                       \
  } while (0)
#define MFR_CHECK_EQ(a, b) MFR_CHECK_OP_(==, a, b)
#define MFR_CHECK_NE(a, b) MFR_CHECK_OP_(!=, a, b)
#define MFR_CHECK_LT(a, b) MFR_CHECK_OP_(<, a, b)
#define MFR_CHECK_LE(a, b) MFR_CHECK_OP_(<=, a, b)
#define MFR_CHECK_GT(a, b) MFR_CHECK_OP_(>, a, b)
#define MFR_CHECK_GE(a, b) MFR_CHECK_OP_(>=, a, b)

/// Propagate an error from an expression returning Result<...>.
#define MFR_TRY(expr)                                     \
  do {                                                    \
    auto&& mfr_try_result_ = (expr);                      \
    if (!mfr_try_result_) return mfr_try_result_.error(); \
  } while (0)
