// LcmOutput writes file://PATH?mode=w logs itself (one buffer instead of LCM's allocation and seven
// fwrite calls per event): the file must be the one LCM's own file provider writes, byte for byte
// except the events' wall-clock times, and read back by LCM's log reader.
#include <doctest/doctest.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "telemetry/lcm_output.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Events of every size up to past the writer's buffer, on channels of several lengths.
struct Event {
  std::string channel;
  std::vector<std::uint8_t> data;
};
std::vector<Event> events() {
  std::vector<Event> e;
  for (int i = 0; i < 3000; ++i) {
    Event x{i % 3 == 0 ? "EXC_STATE/adaptive" : i % 3 == 1 ? "A" : "EXC_TELEMETRY_STATS/slotine_li", {}};
    x.data.resize(static_cast<std::size_t>((i * 37) % 700 + (i == 2999 ? 300000 : 0)));
    for (std::size_t b = 0; b < x.data.size(); ++b) x.data[b] = static_cast<std::uint8_t>(b * 7 + i);
    e.push_back(x);
  }
  return e;
}

}  // namespace

TEST_CASE("telemetry/log file written by LcmOutput equals LCM's own file provider's but the event times, and reads back") {
  const fs::path dir = fs::temp_directory_path() / ("exc-lcm-output-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path ours = dir / "ours.lcm", theirs = dir / "theirs.lcm";
  const std::vector<Event> all = events();
  {
    std::string error;
    auto output = exc::telemetry::LcmOutput::open("file://" + ours.string() + "?mode=w", &error);
    REQUIRE_MESSAGE(output, error);
    for (std::size_t i = 0; i < all.size(); ++i) {
      CHECK(output->publish(all[i].channel.c_str(), all[i].data.data(), all[i].data.size()));
      if (i == 1000) CHECK(output->flush());  // the telemetry thread's flush after a drain
    }
  }
  {
    lcm_t* lcm = lcm_create(("file://" + theirs.string() + "?mode=w").c_str());
    REQUIRE(lcm != nullptr);
    for (const Event& e : all)
      CHECK(lcm_publish(lcm, e.channel.c_str(), e.data.data(), static_cast<unsigned>(e.data.size())) == 0);
    lcm_destroy(lcm);
  }
  // Same bytes but the 8-byte timestamps (at 12 bytes into each event).
  std::vector<std::uint8_t> a = bytes_of(ours), b = bytes_of(theirs);
  REQUIRE(a.size() == b.size());
  std::size_t at = 0;
  for (const Event& e : all) {
    for (int k = 0; k < 8; ++k) a[at + 12 + k] = b[at + 12 + k] = 0;
    at += 28 + e.channel.size() + e.data.size();
  }
  CHECK(at == a.size());
  CHECK(a == b);

  // LCM's reader: every event, in order, numbered from 0, with non-decreasing wall-clock times.
  lcm_eventlog_t* log = lcm_eventlog_create(ours.string().c_str(), "r");
  REQUIRE(log != nullptr);
  std::int64_t count = 0, last_time = 0;
  while (lcm_eventlog_event_t* e = lcm_eventlog_read_next_event(log)) {
    REQUIRE(count < static_cast<std::int64_t>(all.size()));
    const Event& want = all[static_cast<std::size_t>(count)];
    CHECK(e->eventnum == count);
    CHECK(e->timestamp >= last_time);
    last_time = e->timestamp;
    CHECK(std::string(e->channel, static_cast<std::size_t>(e->channellen)) == want.channel);
    CHECK(std::vector<std::uint8_t>(static_cast<std::uint8_t*>(e->data),
                                    static_cast<std::uint8_t*>(e->data) + e->datalen) == want.data);
    lcm_eventlog_free_event(e);
    ++count;
  }
  lcm_eventlog_destroy(log);
  CHECK(count == static_cast<std::int64_t>(all.size()));

  // A file that cannot be created is refused with the URL in the message, as LCM refused it.
  std::string error;
  CHECK(exc::telemetry::LcmOutput::open("file://" + (dir / "no-such-dir" / "x.lcm").string() + "?mode=w", &error) == nullptr);
  CHECK(error.find("no-such-dir") != std::string::npos);
  fs::remove_all(dir);
}
