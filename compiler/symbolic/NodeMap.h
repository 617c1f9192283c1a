// NodeMap<V>: a small open-addressing hash map keyed by node pointer, used for per-call memos
// (evaluation tapes, substitute, CSE, the kernel's lowering) and the per-symbol derivative memo.
// Linear probing, power-of-two capacity from 4 (many memos stay tiny), no erase (only clear); an
// empty map allocates nothing. V must be trivially copyable.
// NodeSet: the visited set of one traversal; a linear scan of an inline array while small.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "symbolic/Arena.h"
#include "symbolic/Expr.h"
#include "symbolic/SmallVec.h"

namespace qdot::sym {

template <class V>
class NodeMap {
 public:
  NodeMap() = default;
  NodeMap(NodeMap&& o) noexcept { swap(o); }
  NodeMap& operator=(NodeMap&& o) noexcept {
    NodeMap(std::move(o)).swap(*this);
    return *this;
  }

  /// Pointer to the value stored for k, or nullptr.
  V* find(Expr k) {
    if (capacity_ == 0) return nullptr;
    for (size_t i = slotOf(k);; i = (i + 1) & mask()) {
      if (slots_[i].key == k) return &slots_[i].value;
      if (slots_[i].key == nullptr) return nullptr;
    }
  }
  const V* find(Expr k) const { return const_cast<NodeMap*>(this)->find(k); }

  /// Inserts (k, v) unless k is present; returns the stored value and whether it was inserted.
  std::pair<V*, bool> insert(Expr k, V v) {
    if ((size_ + 1) * 4 > capacity_ * 3) grow();
    for (size_t i = slotOf(k);; i = (i + 1) & mask()) {
      if (slots_[i].key == k) return {&slots_[i].value, false};
      if (slots_[i].key == nullptr) {
        slots_[i] = {k, std::move(v)};
        ++size_;
        return {&slots_[i].value, true};
      }
    }
  }

  /// Starts loading the slot of k (a traversal about to look up several children issues these
  /// first, so their cache misses overlap instead of following one another).
  void prefetch(Expr k) const {
    if (capacity_) __builtin_prefetch(&slots_[slotOf(k)]);
  }

  size_t size() const { return size_; }
  void swap(NodeMap& o) noexcept {
    std::swap(storage_, o.storage_);
    std::swap(slots_, o.slots_);
    std::swap(capacity_, o.capacity_);
    std::swap(size_, o.size_);
  }
  /// Removes every entry (keeps the capacity).
  void clear() {
    std::fill_n(slots_, capacity_, Slot{});
    size_ = 0;
  }

 private:
  // Trivial slots in storage from allocateLarge: a table of millions of nodes is faulted in and
  // walked at random, so it asks for huge pages (and is cleared after the advice, not before).
  struct Slot {
    Expr key;
    V value;
  };
  static_assert(std::is_trivially_destructible_v<V> && std::is_trivially_copyable_v<V>);

  size_t mask() const { return capacity_ - 1; }
  // Nodes sit in the arena in creation order, and traversals meet nodes created together one after
  // another. So the slot keeps their locality: each 4 KiB page of the arena gets a random window of
  // 256 slots (its base hashed from the page number), and a node's offset in its page places it in
  // that window (nodes are >= 48 bytes apart, so a page's nodes do not collide with each other).
  // Lookups of neighbouring nodes then share cache lines and pages of the table instead of missing
  // the cache once each; windows of different pages overlap at random, as whole keys would.
  size_t slotOf(Expr k) const {
    uint64_t p = reinterpret_cast<uintptr_t>(k);
    uint64_t h = p >> 12;
    h = (h ^ (h >> 31)) * 0x7FB5D329728EA185ull;
    h = (h ^ (h >> 27)) * 0x81DADEF4BC2DD44Dull;
    return static_cast<size_t>((h ^ (h >> 33)) + ((p >> 4) & 255)) & mask();
  }
  void grow() {
    std::unique_ptr<std::byte[]> old = std::move(storage_);
    Slot* oldSlots = slots_;
    size_t oldCapacity = std::exchange(capacity_, capacity_ ? 2 * capacity_ : 4);
    storage_ = allocateLarge<std::byte>(capacity_ * sizeof(Slot));
    slots_ = reinterpret_cast<Slot*>(storage_.get());
    std::uninitialized_fill_n(slots_, capacity_, Slot{});
    size_ = 0;
    for (size_t i = 0; i < oldCapacity; ++i)
      if (oldSlots[i].key) insert(oldSlots[i].key, oldSlots[i].value);
  }

  std::unique_ptr<std::byte[]> storage_;
  Slot* slots_ = nullptr;
  size_t capacity_ = 0;  // a power of two, or 0
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
