// NodeMap<V>: a small open-addressing hash map keyed by node pointer, used for per-call memos
// (evaluation tapes, substitute, CSE) and the per-symbol derivative memo. Linear probing,
// power-of-two capacity from 4 (many memos stay tiny), no erase (only clear); an empty map
// allocates nothing.
// NodeSet: the visited set of one traversal; a linear scan of an inline array while small.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "symbolic/Expr.h"
#include "symbolic/SmallVec.h"

namespace qdot::sym {

template <class V>
class NodeMap {
 public:
  /// Pointer to the value stored for k, or nullptr.
  V* find(Expr k) {
    if (slots_.empty()) return nullptr;
    for (size_t i = slotOf(k);; i = (i + 1) & mask()) {
      if (slots_[i].first == k) return &slots_[i].second;
      if (slots_[i].first == nullptr) return nullptr;
    }
  }
  const V* find(Expr k) const { return const_cast<NodeMap*>(this)->find(k); }

  /// Inserts (k, v) unless k is present; returns the stored value and whether it was inserted.
  std::pair<V*, bool> insert(Expr k, V v) {
    if ((size_ + 1) * 4 > slots_.size() * 3) grow();
    for (size_t i = slotOf(k);; i = (i + 1) & mask()) {
      if (slots_[i].first == k) return {&slots_[i].second, false};
      if (slots_[i].first == nullptr) {
        slots_[i] = {k, std::move(v)};
        ++size_;
        return {&slots_[i].second, true};
      }
    }
  }

  size_t size() const { return size_; }
  /// Removes every entry (keeps the capacity).
  void clear() {
    std::fill(slots_.begin(), slots_.end(), std::pair<Expr, V>{});
    size_ = 0;
  }

 private:
  size_t mask() const { return slots_.size() - 1; }
  size_t slotOf(Expr k) const {
    uint64_t h = reinterpret_cast<uintptr_t>(k);
    h = (h ^ (h >> 31)) * 0x7FB5D329728EA185ull;
    h = (h ^ (h >> 27)) * 0x81DADEF4BC2DD44Dull;
    return static_cast<size_t>(h ^ (h >> 33)) & mask();
  }
  void grow() {
    std::vector<std::pair<Expr, V>> old(slots_.empty() ? 4 : slots_.size() * 2);
    old.swap(slots_);
    size_ = 0;
    for (auto& s : old)
      if (s.first) insert(s.first, std::move(s.second));
  }

  std::vector<std::pair<Expr, V>> slots_;
  size_t size_ = 0;
};

/// Visited nodes of one traversal. Most queries touch a handful of nodes: those stay in an inline
/// array (no allocation, a scan of at most kSmall pointers); past that, a NodeMap takes over.
class NodeSet {
 public:
  /// Adds n; true if it was not there yet.
  bool insert(Expr n) {
    if (small_.size() < kSmall) {
      for (Expr s : small_)
        if (s == n) return false;
      small_.push_back(n);
      return true;
    }
    if (small_.size() == kSmall && big_.size() == 0)
      for (Expr s : small_) big_.insert(s, 1);
    return big_.insert(n, 1).second;
  }
  size_t size() const { return big_.size() ? big_.size() : small_.size(); }

 private:
  static constexpr size_t kSmall = 32;
  SmallVec<Expr, kSmall> small_;
  NodeMap<char> big_;
};

}  // namespace qdot::sym
