#pragma once
// A queue of fixed capacity between two pipeline threads: a full queue makes the producer
// wait (back-pressure instead of unbounded memory), a closed queue lets the consumer drain
// what is left and then tells it that nothing more comes. A producer that must not wait (a
// live sensor's scans) uses the pushes that never block: one that drops the oldest item, one
// that tells the queue is full, and one for small items that may exceed the capacity.

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace featsense::mapping {

template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  /// Waits while the queue is full. Returns false (dropping the item) once it is closed.
  bool push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// What a push that never waits did.
  enum class Pushed { kQueued, kDroppedOldest, kClosed };

  /// Never waits: a full queue drops its oldest item to make room (the freshest data wins),
  /// moved into `dropped` where given.
  Pushed push_dropping_oldest(T item, T* dropped = nullptr) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return Pushed::kClosed;
    Pushed outcome = Pushed::kQueued;
    if (items_.size() >= capacity_) {
      if (dropped != nullptr) *dropped = std::move(items_.front());
      items_.pop_front();
      outcome = Pushed::kDroppedOldest;
    }
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return outcome;
  }

  /// Never waits and never drops: for small items (a pose) that must keep their place in
  /// line even while the queue holds its capacity of large ones. False once closed.
  bool push_past_capacity(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// Whether a push would wait now.
  bool full() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size() >= capacity_;
  }

  /// Items waiting now.
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t capacity() const { return capacity_; }

  /// Waits for an item; nullopt once the queue is closed and empty.
  std::optional<T> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  /// No more pushes; what is queued can still be popped.
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_full_.notify_all();
    not_empty_.notify_all();
  }

  /// Closes and drops what is queued (when the consumer failed).
  void abandon() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    items_.clear();
    not_full_.notify_all();
    not_empty_.notify_all();
  }

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_full_;
  std::condition_variable not_empty_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace featsense::mapping
