// The bus backends: in-memory broadcast semantics, fault injection rates, SocketCAN failing cleanly.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "hal/fault_injecting_bus.hpp"
#include "hal/memory_bus.hpp"
#include "hal/socketcan_bus.hpp"
#include "port_fixtures.hpp"

using namespace exc::hal;
using namespace exc::hal::test;

namespace {
std::int64_t fake_clock(void* context) { return ++*static_cast<std::int64_t*>(context); }
}  // namespace

TEST_CASE("hal/memory bus delivers each frame to every other node in order, never to the sender") {
  MemoryBusHub hub;
  MemoryBusNode* a = hub.attach(16);
  MemoryBusNode* b = hub.attach(16);
  MemoryBusNode* c = hub.attach(16);
  REQUIRE((a && b && c));
  CHECK(a->send(frame_with(0x100, 1)));
  CHECK(a->send(frame_with(0x101, 2)));
  CHECK(b->send(frame_with(0x102, 3)));

  CanFrame f;
  CHECK(a->pending() == 1);  // only b's frame
  REQUIRE(a->receive(f));
  CHECK(f.id == 0x102);
  CHECK_FALSE(a->receive(f));

  for (MemoryBusNode* node : {b}) {
    REQUIRE(node->receive(f));
    CHECK(f.id == 0x100);
    CHECK(f.data[0] == 1);
    REQUIRE(node->receive(f));
    CHECK(f.id == 0x101);
    CHECK_FALSE(node->receive(f));
  }
  const std::uint32_t order[] = {0x100, 0x101, 0x102};
  for (std::uint32_t id : order) {
    REQUIRE(c->receive(f));
    CHECK(f.id == id);
    CHECK(f.timestamp_ns > 0);
  }
  CHECK_FALSE(c->wait_readable(0));
  CHECK(hub.frames_sent() == 3);
}

TEST_CASE("hal/memory bus counts overflow of a full receive ring and keeps the oldest frames") {
  std::int64_t now = 0;
  MemoryBusHub hub(&fake_clock, &now);
  MemoryBusNode* tx = hub.attach(4);
  MemoryBusNode* rx = hub.attach(4);
  for (int i = 0; i < 6; ++i) tx->send(frame_with(0x100, static_cast<std::uint8_t>(i)));
  CHECK(rx->overflows() == 2);
  CanFrame f;
  for (int i = 0; i < 4; ++i) {
    REQUIRE(rx->receive(f));
    CHECK(f.data[0] == i);
    CHECK(f.timestamp_ns == i + 1);  // stamped by the hub's clock at send
  }
  // Invalid frames are refused at send: an ID above 11 bits, 9 bytes (neither classical nor an FD
  // length), more than 8 bytes classical, a bit-rate switch on a classical frame.
  CanFrame bad = frame_with(0x800, 0);
  CHECK_FALSE(tx->send(bad));
  bad = frame_with(0x100, 0, true);
  bad.len = 9;
  CHECK_FALSE(tx->send(bad));
  bad = frame_with(0x100, 0, false, 12);
  CHECK_FALSE(tx->send(bad));
  bad = frame_with(0x100, 0);
  bad.brs = true;
  CHECK_FALSE(tx->send(bad));
  CHECK(rx->pending() == 0);
}

TEST_CASE("hal/memory bus carries CAN FD frames of every length whole") {
  MemoryBusHub hub;
  MemoryBusNode* tx = hub.attach(32);
  MemoryBusNode* rx = hub.attach(32);
  const std::uint8_t lengths[] = {0, 1, 8, 12, 16, 20, 24, 32, 48, 64};
  for (std::uint8_t len : lengths) REQUIRE(tx->send(frame_with(0x180, len, true, len)));
  CanFrame f;
  for (std::uint8_t len : lengths) {
    REQUIRE(rx->receive(f));
    const CanFrame sent = frame_with(0x180, len, true, len);
    CHECK(f.fd);
    CHECK(f.brs);
    CHECK(f.len == len);
    for (int i = 0; i < kCanFdMaxLength; ++i) CHECK(f.data[i] == sent.data[i]);
  }
}

TEST_CASE("hal/memory bus refuses more than kMaxNodes nodes") {
  MemoryBusHub hub;
  for (std::size_t i = 0; i < MemoryBusHub::kMaxNodes; ++i) CHECK(hub.attach(2) != nullptr);
  CHECK(hub.attach(2) == nullptr);
}

TEST_CASE("hal/fault injection drops, corrupts and delays the configured fractions for a seed") {
  MemoryBusHub hub;
  MemoryBusNode* tx_node = hub.attach(8);
  MemoryBusNode* rx = hub.attach(128);
  FaultInjection config;
  config.drop_fraction = 0.05;
  config.corrupt_fraction = 0.03;
  config.delay_fraction = 0.02;
  config.delay_frames = 3;
  config.seed = 42;
  FaultInjectingBus faulty(*tx_node, config);

  constexpr int kFrames = 200000;
  std::uint64_t received = 0, corrupted = 0, reordered = 0;
  std::uint32_t last_sequence = 0;
  for (int i = 0; i < kFrames; ++i) {
    CanFrame f;
    f.id = 0x200;
    f.len = 8;
    const auto seq = static_cast<std::uint32_t>(i + 1);
    for (int k = 0; k < 4; ++k) f.data[k] = static_cast<std::uint8_t>(seq >> (8 * k));
    for (int k = 4; k < 8; ++k) f.data[k] = static_cast<std::uint8_t>(~f.data[k - 4]);  // check bytes
    faulty.send(f);
    CanFrame got;
    while (rx->receive(got)) {
      ++received;
      bool intact = true;
      for (int k = 4; k < 8; ++k) intact &= got.data[k] == static_cast<std::uint8_t>(~got.data[k - 4]);
      if (!intact) {
        ++corrupted;
        continue;
      }
      std::uint32_t s = 0;
      for (int k = 0; k < 4; ++k) s |= static_cast<std::uint32_t>(got.data[k]) << (8 * k);
      if (s < last_sequence) ++reordered;
      last_sequence = std::max(last_sequence, s);
    }
  }
  faulty.release_delayed();
  CanFrame got;
  while (rx->receive(got)) ++received;

  const auto& stats = faulty.stats();
  MESSAGE("dropped ", stats.dropped, ", corrupted ", stats.corrupted, ", delayed ", stats.delayed, " of ", kFrames);
  // Binomial standard deviation for 200000 frames is below 0.05% absolute: 0.3% is a wide margin.
  CHECK(std::fabs(stats.dropped / double(kFrames) - 0.05) < 0.003);
  CHECK(std::fabs(stats.corrupted / double(kFrames) - 0.03) < 0.003);
  CHECK(std::fabs(stats.delayed / double(kFrames) - 0.02) < 0.003);
  // What the receiver saw agrees with the decorator's own counts.
  CHECK(received == kFrames - stats.dropped);
  CHECK(corrupted == stats.corrupted);
  // A delayed frame shows as out of order unless all frames sent after it were lost too (rare).
  CHECK(reordered <= stats.delayed);
  CHECK(reordered >= stats.delayed * 99 / 100);

  // Same seed, same damage.
  MemoryBusHub hub2;
  MemoryBusNode* tx2 = hub2.attach(8);
  hub2.attach(8);
  FaultInjectingBus again(*tx2, config);
  for (int i = 0; i < kFrames; ++i) again.send(frame_with(0x200, 0));
  CHECK(again.stats().dropped == stats.dropped);
  CHECK(again.stats().corrupted == stats.corrupted);
}

TEST_CASE("hal/socketcan fails cleanly naming the interface and the errno text") {
  std::string why;
  const bool supported = SocketCanBus::kernel_supports_can(&why);
  std::string error;
  const std::uint32_t ids[] = {0x080, 0x100};
  auto bus = SocketCanBus::open("nosuchcan0", ids, 2, error);
  CHECK(bus == nullptr);
  CHECK(error.find("nosuchcan0") != std::string::npos);
  MESSAGE(error);
  if (!supported) {
    CHECK(error.find("socket(PF_CAN") != std::string::npos);
    MESSAGE("no SocketCAN in this kernel (", why, "): checked the error of socket() only");
  } else {
    CHECK(error.find("if_nametoindex") != std::string::npos);
  }
  auto too_long = SocketCanBus::open("a-name-longer-than-ifnamsiz", ids, 2, error);
  CHECK(too_long == nullptr);
  CHECK(error.find("a-name-longer-than-ifnamsiz") != std::string::npos);
}
