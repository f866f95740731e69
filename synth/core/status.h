// Errors as values. synth/ never throws across its API, never exits the process and
// knows nothing about HTTP: one place in the server maps StatusCode to HTTP statuses.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace solidtex {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,    // malformed or out-of-range input; `field` names it
  kNotFound,
  kUnsupported,        // well-formed but of a kind we do not handle (e.g. image format)
  kTooLarge,           // exceeds a configured limit (bytes, pixels, voxels)
  kCorrupt,            // data fails its own consistency checks (checksum, truncated, decode error)
  kVersionMismatch,    // a stored file written by an incompatible format version
  kCancelled,          // an interrupter asked to stop
  kDeadlineExceeded,
  kResourceExhausted,  // queue full, budget spent
  kAlreadyExists,
  kFailedPrecondition, // the target is not in a state that allows this (in use, not ready)
  kUnprocessable,      // well-formed input whose content cannot be used (e.g. image too big in pixels)
  kRateLimited,        // too many concurrent operations of this kind for now; retry later
  kUnavailable,        // a service this one depends on (the store) cannot be reached or refuses service now
  kInternal,
  kIo,                 // the operating system refused a read or write
};

const char* status_code_name(StatusCode code);

class Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message, std::string field = {})
      : code_(code), message_(std::move(message)), field_(std::move(field)) {}

  static Status ok() { return {}; }
  bool is_ok() const { return code_ == StatusCode::kOk; }
  explicit operator bool() const { return is_ok(); }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // The input field or parameter the error is about, e.g. "neighborhood" or "image"; may be empty.
  const std::string& field() const { return field_; }
  // "invalid_argument: neighborhood: must be odd" style text for logs and the CLI.
  std::string to_string() const;
  // Prefixes the message with context ("loading wood.png: ...") keeping code and field.
  Status with_context(const std::string& context) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
  std::string field_;
};

// A value or the Status explaining why there is none.
template <typename T>
class Result {
 public:
  Result(T value) : v_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : v_(std::move(status)) { assert(!std::get<Status>(v_).is_ok()); }  // NOLINT

  bool is_ok() const { return std::holds_alternative<T>(v_); }
  explicit operator bool() const { return is_ok(); }
  const Status& status() const {
    static const Status kOk;
    return is_ok() ? kOk : std::get<Status>(v_);
  }
  T& value() & { return std::get<T>(v_); }
  const T& value() const& { return std::get<T>(v_); }
  T&& value() && { return std::get<T>(std::move(v_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> v_;
};

#define SOLIDTEX_CONCAT_INNER(a, b) a##b
#define SOLIDTEX_CONCAT(a, b) SOLIDTEX_CONCAT_INNER(a, b)

// Returns early with the Status if `expr` (a Status) is not ok.
#define SOLIDTEX_RETURN_IF_ERROR(expr)                 \
  do {                                                 \
    ::solidtex::Status _st = (expr);                   \
    if (!_st.is_ok()) return _st;                      \
  } while (0)

// `SOLIDTEX_ASSIGN_OR_RETURN(auto x, make_x());`
#define SOLIDTEX_ASSIGN_OR_RETURN(lhs, expr)                                 \
  auto SOLIDTEX_CONCAT(_res_, __LINE__) = (expr);                            \
  if (!SOLIDTEX_CONCAT(_res_, __LINE__).is_ok())                             \
    return SOLIDTEX_CONCAT(_res_, __LINE__).status();                        \
  lhs = std::move(SOLIDTEX_CONCAT(_res_, __LINE__)).value()

}  // namespace solidtex
