// SymbolSlots<T>: one value per symbol id, kept in pages of ids allocated on first write. A program
// builder binds and lowers a few symbols spread over a large model's whole id range (parameters,
// a boundary row's elements, the temporaries CSE creates last, after millions of elements): a
// dense vector would cost every id below the largest, pages cost only the ranges written.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

namespace qdot::kernel {

template <class T>
class SymbolSlots {
 public:
  /// `none`: the value of every id not written.
  explicit SymbolSlots(T none) : none_(none) {}

  /// The value of `id` (none if not written).
  T get(uint32_t id) const {
    const T* v = find(id);
    return v ? *v : none_;
  }
  /// The slot of `id` if its page exists (it then holds none until written), else nullptr.
  const T* find(uint32_t id) const {
    size_t page = id >> kPageBits;
    return page < pages_.size() && pages_[page] ? &pages_[page][id & kPageMask] : nullptr;
  }
  /// The slot of `id`, its page allocated (filled with none) if needed.
  T& at(uint32_t id) {
    size_t page = id >> kPageBits;
    if (page >= pages_.size()) pages_.resize(page + 1);
    if (!pages_[page]) {
      pages_[page] = std::make_unique<T[]>(kPageSize);
      std::fill_n(pages_[page].get(), kPageSize, none_);
    }
    return pages_[page][id & kPageMask];
  }

 private:
  static constexpr unsigned kPageBits = 10;
  static constexpr size_t kPageSize = size_t{1} << kPageBits;
  static constexpr uint32_t kPageMask = kPageSize - 1;
  std::vector<std::unique_ptr<T[]>> pages_;
  T none_;
};

}  // namespace qdot::kernel
