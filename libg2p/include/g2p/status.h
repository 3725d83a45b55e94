// Status and Result<T>: how every public libg2p function reports failure.
// No exception crosses the public API. Every message names what failed and
// where ("SheenChair.glb: mesh 3 face 17: index 912 out of range (512 vertices)").
#pragma once

#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "g2p/visibility.h"

namespace g2p {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,  // the caller passed something unusable (options, a mesh)
  kNotFound,         // a file, class or backend name that does not exist
  kIoError,          // reading or writing failed at the operating-system level
  kParseError,       // a file exists but its content is malformed
  kUnsupported,      // a valid request this build or format cannot serve
  kCancelled,        // the caller cancelled the operation
  kUnavailable,      // an optional service (network, model) could not be reached
  kInternal,         // a bug or an unexpected failure inside libg2p
  kOutOfMemory,      // the work needs more memory than the limit or the machine has
};

// Stable lower-case name of a code, e.g. "parse error".
G2P_API const char* to_string(StatusCode code);

class [[nodiscard]] G2P_API Status {
 public:
  Status() = default;  // OK
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return {}; }
  static Status InvalidArgument(std::string m) { return {StatusCode::kInvalidArgument, std::move(m)}; }
  static Status NotFound(std::string m) { return {StatusCode::kNotFound, std::move(m)}; }
  static Status IoError(std::string m) { return {StatusCode::kIoError, std::move(m)}; }
  static Status ParseError(std::string m) { return {StatusCode::kParseError, std::move(m)}; }
  static Status Unsupported(std::string m) { return {StatusCode::kUnsupported, std::move(m)}; }
  static Status Cancelled(std::string m) { return {StatusCode::kCancelled, std::move(m)}; }
  static Status Unavailable(std::string m) { return {StatusCode::kUnavailable, std::move(m)}; }
  static Status Internal(std::string m) { return {StatusCode::kInternal, std::move(m)}; }
  static Status OutOfMemory(std::string m) { return {StatusCode::kOutOfMemory, std::move(m)}; }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // "parse error: <message>", or "ok".
  std::string to_string() const;

  // Returns a copy whose message is prefixed with `where` ("file.glb: ...").
  Status with_context(const std::string& where) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

// A value of type T or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] Result {
  static_assert(!std::is_same_v<std::decay_t<T>, Status>, "Result<Status> makes no sense");

 public:
  Result(T value) : value_(std::move(value)) {}         // NOLINT(google-explicit-constructor)
  Result(Status status) : status_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    if (status_.ok()) status_ = Status::Internal("Result constructed from an OK status without a value");
  }

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }

  // Access to the value; calling these on an error Result is a programming
  // error (checked by std::optional in debug builds of the standard library).
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T& operator*() & { return *value_; }
  const T& operator*() const& { return *value_; }
  T&& operator*() && { return std::move(*value_); }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }

  template <typename U>
  T value_or(U&& fallback) const& {
    return ok() ? *value_ : static_cast<T>(std::forward<U>(fallback));
  }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace g2p

// Returns early from a function returning Status or Result<T> when `expr`
// (a Status) is an error.
#define G2P_RETURN_IF_ERROR(expr)              \
  do {                                         \
    ::g2p::Status g2p_status_ = (expr);        \
    if (!g2p_status_.ok()) return g2p_status_; \
  } while (0)
