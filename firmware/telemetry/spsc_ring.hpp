#pragma once
// A lock-free single-producer single-consumer ring of fixed-size byte slots. push() never blocks: when
// the ring is full it overwrites the oldest message and counts it. Producers that must not lose
// messages (or must drop the newest instead) check full() first (TelemetryPublisher does).
//
// Why not a plain head/tail ring: with "drop the oldest" the producer must reuse a slot the consumer
// may be copying at that very moment. Each slot therefore carries a sequence word that says which
// message position it holds and in what state (being written, complete, consumed), in the manner of
// a sequence lock:
//  - the producer takes a slot with one atomic exchange; if the slot held a complete message the
//    consumer had not claimed, that message is dropped and counted (the exchange is the single
//    point that decides, so every message is counted exactly once: consumed or dropped);
//  - the consumer copies the payload out, then claims it with a compare-and-swap from "complete"
//    to "consumed"; if the producer got there first the copy is discarded.
// Payload words are std::atomic<uint64_t> accessed relaxed, so a torn read is detected by the
// sequence word and is never undefined behaviour. Nothing here allocates after construction.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace exc::telemetry {

// Counters of a ring. Each is monotonic.
struct RingCounters {
  std::uint64_t pushed = 0;             // messages the producer wrote into a slot
  std::uint64_t dropped_overflow = 0;   // complete messages overwritten before the consumer took them
  std::uint64_t dropped_too_large = 0;  // messages refused because they exceed the slot size
};

// SlotBytes: payload capacity of one slot (multiple of 8). SlotCount: power of two.
template <std::size_t SlotBytes, std::size_t SlotCount>
class SpscRing {
  static_assert(SlotCount >= 2 && (SlotCount & (SlotCount - 1)) == 0,
                "SlotCount must be a power of two");
  static_assert(SlotBytes >= 8 && SlotBytes % 8 == 0, "SlotBytes must be a multiple of 8");

 public:
  static constexpr std::size_t slot_bytes = SlotBytes;
  static constexpr std::size_t slot_count = SlotCount;

  // One message as the consumer receives it.
  struct Message {
    std::uint16_t tag = 0;     // the producer's label (the telemetry channel id)
    std::uint32_t size = 0;    // payload bytes
    std::uint64_t position = 0;  // 0, 1, 2, ... in push order: gaps mean dropped messages
    alignas(8) std::uint8_t bytes[SlotBytes];
  };

  SpscRing() {
    for (auto& slot : slots_) slot.sequence.store(0, std::memory_order_relaxed);
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer only. Copies `size` bytes into the next slot, overwriting the oldest message if the
  // ring is full. Returns false (and counts it) only if the message does not fit a slot.
  bool push(std::uint16_t tag, const void* data, std::size_t size) {
    if (size > SlotBytes) {
      too_large_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    const std::uint64_t position = head_.load(std::memory_order_relaxed);
    Slot& slot = slots_[position & (SlotCount - 1)];
    const std::uint64_t previous =
        slot.sequence.exchange(encode_sequence(position, State::writing), std::memory_order_relaxed);
    // Boehm's sequence-lock writer: the fence orders the exchange before the payload stores for a
    // reader that fences after its payload loads.
    std::atomic_thread_fence(std::memory_order_release);
    if (state_of(previous) == State::complete) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
    }
    slot.header.store(static_cast<std::uint64_t>(tag) << 32 | static_cast<std::uint64_t>(size),
                      std::memory_order_relaxed);
    // Whole words, then the last one's bytes (zero-padded): fixed-size copies the compiler inlines.
    const std::size_t whole = size / 8, tail = size % 8;
    const auto* source = static_cast<const std::uint8_t*>(data);
    for (std::size_t w = 0; w < whole; ++w) {
      std::uint64_t word;
      std::memcpy(&word, source + w * 8, 8);
      slot.payload[w].store(word, std::memory_order_relaxed);
    }
    if (tail != 0) {
      std::uint64_t word = 0;
      std::memcpy(&word, source + whole * 8, tail);
      slot.payload[whole].store(word, std::memory_order_relaxed);
    }
    slot.sequence.store(encode_sequence(position, State::complete), std::memory_order_release);
    head_.store(position + 1, std::memory_order_release);
    pushed_.fetch_add(1, std::memory_order_relaxed);
    const std::size_t waiting = occupancy();
    if (waiting > high_water_.load(std::memory_order_relaxed)) high_water_.store(waiting, std::memory_order_relaxed);
    return true;
  }

  // Consumer only. Copies the oldest message still in the ring into `out`; false if there is none.
  bool pop(Message& out) {
    for (;;) {
      const std::uint64_t head = head_.load(std::memory_order_acquire);
      if (next_ >= head) return false;
      // Positions older than head - SlotCount were overwritten (the producer counted them).
      if (head - next_ > SlotCount) next_ = head - SlotCount;
      Slot& slot = slots_[next_ & (SlotCount - 1)];
      const std::uint64_t expected = encode_sequence(next_, State::complete);
      const std::uint64_t seen = slot.sequence.load(std::memory_order_acquire);
      if (seen != expected) {
        // Either the producer has since overwritten this slot with a newer position (skip ahead
        // and retry) or it is writing this very position right now (nothing complete to take).
        if (position_of(seen) > next_) {
          ++next_;
          continue;
        }
        return false;
      }
      const std::uint64_t header = slot.header.load(std::memory_order_relaxed);
      const auto size = static_cast<std::uint32_t>(header & 0xffffffffu);
      if (size > SlotBytes) return false;  // cannot happen with a complete slot; be safe
      const std::size_t whole = size / 8, tail = size % 8;
      for (std::size_t w = 0; w < whole; ++w) {
        const std::uint64_t word = slot.payload[w].load(std::memory_order_relaxed);
        std::memcpy(out.bytes + w * 8, &word, 8);
      }
      if (tail != 0) {
        const std::uint64_t word = slot.payload[whole].load(std::memory_order_relaxed);
        std::memcpy(out.bytes + whole * 8, &word, tail);
      }
      std::atomic_thread_fence(std::memory_order_acquire);
      std::uint64_t claim = expected;
      const bool claimed = slot.sequence.compare_exchange_strong(
          claim, encode_sequence(next_, State::consumed), std::memory_order_acq_rel,
          std::memory_order_relaxed);
      const std::uint64_t position = next_;
      ++next_;
      consumed_.store(next_, std::memory_order_release);
      if (!claimed) continue;  // overwritten while we copied: the producer counted it as dropped
      out.tag = static_cast<std::uint16_t>(header >> 32);
      out.size = size;
      out.position = position;
      return true;
    }
  }

  // Producer only: messages written and not yet taken by the consumer (0 .. SlotCount). A producer
  // that must not lose messages waits while full(); one with a deadline refuses the new message.
  std::size_t occupancy() const {
    return static_cast<std::size_t>(head_.load(std::memory_order_relaxed) - consumed_.load(std::memory_order_acquire));
  }
  bool full() const { return occupancy() >= SlotCount; }
  // The most messages that were waiting at once (producer-side, after each push).
  std::size_t high_water() const { return high_water_.load(std::memory_order_relaxed); }

  // Producer only: counts a message refused before push (e.g. its encoding did not fit a slot).
  void note_too_large() { too_large_.fetch_add(1, std::memory_order_relaxed); }

  // Any thread: a snapshot of the counters (each counter is exact; together only approximately
  // simultaneous).
  RingCounters counters() const {
    RingCounters c;
    c.pushed = pushed_.load(std::memory_order_relaxed);
    c.dropped_overflow = dropped_.load(std::memory_order_relaxed);
    c.dropped_too_large = too_large_.load(std::memory_order_relaxed);
    return c;
  }

 private:
  enum class State : std::uint64_t { empty = 0, writing = 1, complete = 2, consumed = 3 };
  static constexpr std::uint64_t encode_sequence(std::uint64_t position, State state) {
    return position << 2 | static_cast<std::uint64_t>(state);
  }
  static constexpr State state_of(std::uint64_t sequence) { return State(sequence & 3u); }
  static constexpr std::uint64_t position_of(std::uint64_t sequence) { return sequence >> 2; }

  struct alignas(64) Slot {
    std::atomic<std::uint64_t> sequence{0};
    std::atomic<std::uint64_t> header{0};  // tag << 32 | size
    std::array<std::atomic<std::uint64_t>, SlotBytes / 8> payload{};
  };

  std::array<Slot, SlotCount> slots_{};
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next position the producer writes
  alignas(64) std::uint64_t next_ = 0;               // consumer-private: next position to read
  std::atomic<std::uint64_t> consumed_{0};           // next_, published for the producer's occupancy
  alignas(64) std::atomic<std::size_t> high_water_{0};
  alignas(64) std::atomic<std::uint64_t> pushed_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> too_large_{0};
};

}  // namespace exc::telemetry
