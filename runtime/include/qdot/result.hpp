// Result<T>: the outcome of a fallible backend call — a value, or the sentence saying why there is
// none (no out-parameters). Status = Result<void>. ModelPtr owns a QdotModel (destroy() on release).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "qdot/model_abi.h"

namespace qdot {

/// The failure of a Result: `return Error{"why"};`.
struct Error {
  std::string message;
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}
  Result(Error e) : error_(std::move(e.message)) {}
  Result(Result&&) noexcept = default;
  Result& operator=(Result&&) noexcept = default;
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  /// The value (only if ok()).
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }
  /// Why there is no value ("" if ok()).
  const std::string& error() const { return error_; }

 private:
  std::optional<T> value_;
  std::string error_;
};

/// Success or the reason of a failure.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error e) : error_(std::move(e.message)), ok_(false) {}

  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const std::string& error() const { return error_; }

 private:
  std::string error_;
  bool ok_ = true;
};
using Status = Result<void>;

/// Calls model->destroy(model).
struct ModelDeleter {
  void operator()(QdotModel* m) const {
    if (m) m->destroy(m);
  }
};
/// A QdotModel owned by the caller.
using ModelPtr = std::unique_ptr<QdotModel, ModelDeleter>;

}  // namespace qdot
