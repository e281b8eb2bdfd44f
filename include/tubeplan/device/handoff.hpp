#pragma once
// Lock-free hand-offs out of the servo thread: nothing here locks, waits or allocates on the
// writer's side.
//  - Seqlock<T>: the latest value for a reader that only wants the newest (the display). The
//    payload is kept in atomic words, so a torn read is detected by the sequence and
//    retried, and there is no data race in the C++ memory model (Boehm, "Can seqlocks get along
//    with programming language memory models?", 2012), which keeps ThreadSanitizer quiet.
//  - SpscRing<T>: every value, in order, from one producer to one consumer (the judge and the
//    recorder); when full the producer drops and counts, it never waits.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <type_traits>

namespace tubeplan::device {

template <class T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "a seqlock copies its payload word by word");
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

 public:
  /// One writer only.
  void Store(const T& value) {
    std::array<std::uint64_t, kWords> words{};
    std::memcpy(words.data(), &value, sizeof(T));
    const std::uint64_t s = sequence_.load(std::memory_order_relaxed);
    sequence_.store(s + 1, std::memory_order_relaxed);  // odd: a write is under way
    // Release stores, not a fence (ThreadSanitizer does not model fences): a reader that sees a
    // new word also sees the odd sequence stored before it.
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(words[i], std::memory_order_release);
    sequence_.store(s + 2, std::memory_order_release);
  }
  /// Any number of readers; nullopt before the first Store. Retries while a write overlaps.
  std::optional<T> Load() const {
    std::array<std::uint64_t, kWords> words{};
    for (;;) {
      const std::uint64_t before = sequence_.load(std::memory_order_acquire);
      if (before == 0) return std::nullopt;
      if (before & 1u) continue;
      // Acquire loads keep the second sequence load after them (no fence, as in Store).
      for (std::size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_acquire);
      if (sequence_.load(std::memory_order_relaxed) == before) break;
    }
    T value;
    std::memcpy(static_cast<void*>(&value), words.data(), sizeof(T));
    return value;
  }
  /// One attempt, never waits: false (and `value` unchanged) before the first Store or when a
  /// write overlapped. For a reader that must not spin on a writer that was preempted mid-write
  /// (the servo thread reading a network device's receiver).
  bool TryLoad(T& value) const {
    std::array<std::uint64_t, kWords> words{};
    const std::uint64_t before = sequence_.load(std::memory_order_acquire);
    if (before == 0 || (before & 1u)) return false;
    for (std::size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) != before) return false;
    std::memcpy(static_cast<void*>(&value), words.data(), sizeof(T));
    return true;
  }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

template <class T>
class SpscRing {
 public:
  /// Capacity is rounded up to a power of two; the storage is allocated here, once.
  explicit SpscRing(std::size_t capacity) {
    std::size_t c = 1;
    while (c < capacity) c <<= 1;
    mask_ = c - 1;
    slots_ = std::make_unique<T[]>(c);
  }
  /// Producer: false (and counted) when full.
  bool TryPush(const T& value) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) > mask_) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  /// Consumer: the oldest value, if any.
  bool TryPop(T& value) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    value = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::size_t capacity() const { return mask_ + 1; }

 private:
  std::unique_ptr<T[]> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace tubeplan::device
