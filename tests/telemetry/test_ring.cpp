// The ring alone: drop-oldest accounting, ordering under a concurrent consumer, size limits.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "telemetry/spsc_ring.hpp"

using exc::telemetry::SpscRing;

namespace {

// Payload: the push index as 8 bytes, then filler bytes derived from it (so a torn copy shows).
template <class Ring>
void push_index(Ring& ring, std::uint64_t index, std::size_t size) {
  std::uint8_t bytes[Ring::slot_bytes] = {};
  std::memcpy(bytes, &index, sizeof index);
  for (std::size_t i = 8; i < size; ++i) bytes[i] = static_cast<std::uint8_t>(index * 31 + i);
  REQUIRE(ring.push(static_cast<std::uint16_t>(index % 7), bytes, size));
}

template <class Message>
std::uint64_t index_of(const Message& m) {
  std::uint64_t index = 0;
  std::memcpy(&index, m.bytes, sizeof index);
  return index;
}

template <class Message>
bool filler_intact(const Message& m) {
  const std::uint64_t index = index_of(m);
  for (std::size_t i = 8; i < m.size; ++i) {
    if (m.bytes[i] != static_cast<std::uint8_t>(index * 31 + i)) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("telemetry/ring overflow drops the oldest and counts each drop") {
  using Ring = SpscRing<64, 8>;
  auto ring = std::make_unique<Ring>();
  for (std::uint64_t i = 0; i < 20; ++i) push_index(*ring, i, 40);
  // 20 pushed into 8 slots with nobody reading: the first 12 are gone, the last 8 remain.
  CHECK(ring->counters().pushed == 20);
  CHECK(ring->counters().dropped_overflow == 12);
  auto message = std::make_unique<Ring::Message>();
  std::vector<std::uint64_t> got;
  while (ring->pop(*message)) {
    CHECK(message->size == 40);
    CHECK(message->tag == index_of(*message) % 7);
    CHECK(message->position == index_of(*message));
    CHECK(filler_intact(*message));
    got.push_back(index_of(*message));
  }
  CHECK(got == std::vector<std::uint64_t>{12, 13, 14, 15, 16, 17, 18, 19});
  CHECK_FALSE(ring->pop(*message));
  // Consumed messages are not counted as dropped when their slots are reused.
  for (std::uint64_t i = 20; i < 28; ++i) push_index(*ring, i, 16);
  CHECK(ring->counters().dropped_overflow == 12);
  int n = 0;
  while (ring->pop(*message)) CHECK(index_of(*message) == 20 + n++);
  CHECK(n == 8);
}

TEST_CASE("telemetry/ring refuses a message larger than a slot and counts it") {
  using Ring = SpscRing<32, 4>;
  auto ring = std::make_unique<Ring>();
  std::uint8_t bytes[40] = {};
  CHECK_FALSE(ring->push(0, bytes, 33));
  CHECK(ring->push(0, bytes, 32));
  CHECK(ring->counters().dropped_too_large == 1);
  CHECK(ring->counters().pushed == 1);
}

TEST_CASE("telemetry/ring under a concurrent consumer delivers in order, intact, all accounted") {
  // A small ring and a fast producer force overwrites while the consumer copies.
  using Ring = SpscRing<128, 16>;
  auto ring = std::make_unique<Ring>();
  constexpr std::uint64_t total = 400000;
  std::atomic<bool> done{false};
  std::uint64_t consumed = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t torn = 0;
  std::thread consumer([&] {
    auto message = std::make_unique<Ring::Message>();
    std::uint64_t last = 0;
    bool first = true;
    for (;;) {
      const bool finished = done.load(std::memory_order_acquire);
      while (ring->pop(*message)) {
        const std::uint64_t index = index_of(*message);
        if (!first && index <= last) ++out_of_order;
        if (!filler_intact(*message) || message->position != index) ++torn;
        last = index;
        first = false;
        ++consumed;
      }
      if (finished) break;
    }
  });
  for (std::uint64_t i = 0; i < total; ++i) push_index(*ring, i, 8 + (i % 15) * 8);
  done.store(true, std::memory_order_release);
  consumer.join();
  CHECK(out_of_order == 0);
  CHECK(torn == 0);
  const auto counters = ring->counters();
  CHECK(counters.pushed == total);
  // Every message is either consumed or counted as dropped, exactly once.
  CHECK(consumed + counters.dropped_overflow == total);
  MESSAGE("consumed " << consumed << ", dropped " << counters.dropped_overflow);
}
