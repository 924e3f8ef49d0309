// The queue between two pipeline threads: a full queue holds the producer back, a closed one
// lets the consumer drain what is left, an abandoned one drops it and frees a waiting producer.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "featsense/mapping/bounded_queue.hpp"

namespace featsense::mapping {
namespace {

TEST(BoundedQueue, AFullQueueHoldsTheProducerUntilAnItemIsTaken) {
  BoundedQueue<int> queue(2);
  ASSERT_TRUE(queue.push(1));
  ASSERT_TRUE(queue.push(2));
  std::atomic<bool> pushed{false};
  std::thread producer([&] {
    queue.push(3);
    pushed.store(true);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(pushed.load()) << "a third item went into a queue of two";
  EXPECT_EQ(queue.pop(), 1);
  producer.join();
  EXPECT_TRUE(pushed.load());
  EXPECT_EQ(queue.pop(), 2);
  EXPECT_EQ(queue.pop(), 3);
}

TEST(BoundedQueue, AClosedQueueIsDrainedThenEnds) {
  BoundedQueue<int> queue(4);
  queue.push(1);
  queue.push(2);
  queue.close();
  EXPECT_FALSE(queue.push(3));
  EXPECT_EQ(queue.pop(), 1);
  EXPECT_EQ(queue.pop(), 2);
  EXPECT_EQ(queue.pop(), std::nullopt);
}

TEST(BoundedQueue, AbandoningDropsWhatIsQueuedAndFreesAWaitingProducer) {
  BoundedQueue<int> queue(1);
  queue.push(1);
  std::atomic<bool> refused{false};
  std::thread producer([&] { refused.store(!queue.push(2)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.abandon();
  producer.join();
  EXPECT_TRUE(refused.load());
  EXPECT_EQ(queue.pop(), std::nullopt);
}

TEST(BoundedQueue, AWaitingConsumerWakesWhenTheQueueCloses) {
  BoundedQueue<int> queue(1);
  std::optional<int> got = 7;
  std::thread consumer([&] { got = queue.pop(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.close();
  consumer.join();
  EXPECT_EQ(got, std::nullopt);
}

TEST(BoundedQueue, APushThatMustNotWaitDropsTheOldestItem) {
  BoundedQueue<int> queue(2);
  using Pushed = BoundedQueue<int>::Pushed;
  int dropped = 0;
  EXPECT_EQ(queue.push_dropping_oldest(1, &dropped), Pushed::kQueued);
  EXPECT_FALSE(queue.full());
  EXPECT_EQ(queue.push_dropping_oldest(2, &dropped), Pushed::kQueued);
  EXPECT_TRUE(queue.full());
  EXPECT_EQ(queue.push_dropping_oldest(3, &dropped), Pushed::kDroppedOldest);
  EXPECT_EQ(dropped, 1);
  EXPECT_EQ(queue.pop(), 2);
  EXPECT_EQ(queue.pop(), 3);
  queue.close();
  EXPECT_EQ(queue.push_dropping_oldest(4), Pushed::kClosed);
}

TEST(BoundedQueue, SmallItemsMayGoPastTheCapacityInOrder) {
  BoundedQueue<int> queue(1);
  ASSERT_TRUE(queue.push(1));
  EXPECT_TRUE(queue.push_past_capacity(2));  // does not wait on the full queue
  EXPECT_TRUE(queue.push_past_capacity(3));
  EXPECT_EQ(queue.pop(), 1);
  EXPECT_TRUE(queue.full());  // still two in line
  EXPECT_EQ(queue.pop(), 2);
  EXPECT_EQ(queue.pop(), 3);
  queue.abandon();
  EXPECT_FALSE(queue.push_past_capacity(4));
}

}  // namespace
}  // namespace featsense::mapping
