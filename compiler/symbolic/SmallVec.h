// SmallVec<T, N>: a vector of trivially copyable T whose first N elements live inside the object,
// so the builders and traversals that normally hold a handful of operands never touch the heap.
// Grows by doubling (memcpy); only what the symbolic internals need. Not a public header.
#pragma once

#include <cstddef>
#include <cstring>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>

namespace qdot::sym {

template <class T, size_t N>
class SmallVec {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  SmallVec() = default;
  SmallVec(const SmallVec&) = delete;
  SmallVec& operator=(const SmallVec&) = delete;

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T& back() { return data_[size_ - 1]; }
  operator std::span<const T>() const { return {data_, size_}; }

  void push_back(const T& v) {
    if (size_ == capacity_) grow(2 * capacity_);
    data_[size_++] = v;
  }
  template <class... A>
  void emplace_back(A&&... a) {
    push_back(T{std::forward<A>(a)...});
  }
  void pop_back() { --size_; }
  void clear() { size_ = 0; }
  /// Shrinks to n elements (n <= size()).
  void truncate(size_t n) { size_ = n; }
  void reserve(size_t n) {
    if (n > capacity_) grow(n);
  }

 private:
  void grow(size_t capacity) {
    auto bigger = std::make_unique_for_overwrite<T[]>(capacity);
    std::memcpy(static_cast<void*>(bigger.get()), data_, size_ * sizeof(T));
    heap_ = std::move(bigger);
    data_ = heap_.get();
    capacity_ = capacity;
  }

  T inline_[N];
  T* data_ = inline_;
  size_t size_ = 0, capacity_ = N;
  std::unique_ptr<T[]> heap_;
};

}  // namespace qdot::sym
