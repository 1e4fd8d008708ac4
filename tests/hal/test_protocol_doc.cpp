// docs/can-protocol.md's frame and signal tables against the DBC, so the page cannot drift.
#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dbc_reader.hpp"
#include "hal/can_bus_load.hpp"

namespace {

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line.substr(1));
  std::string cell;
  while (std::getline(in, cell, '|')) {
    const auto first = cell.find_first_not_of(' ');
    const auto last = cell.find_last_not_of(' ');
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
  }
  return cells;
}

}  // namespace

TEST_CASE("hal/protocol page lists every DBC frame and signal exactly as the DBC defines them") {
  const auto dbc = exc::test::read_dbc(EXC_CAN_DBC_FILE);
  std::ifstream page(std::string(EXC_SOURCE_DIR) + "/docs/can-protocol.md");
  REQUIRE(page.good());
  std::size_t frame_rows = 0, signal_rows = 0, data_signals = 0;
  for (const auto& m : dbc) data_signals += m.signals.size() - 2;
  std::string line;
  while (std::getline(page, line)) {
    if (line.rfind("| 0x", 0) != 0) continue;
    const auto cells = cells_of(line);
    const auto id = static_cast<std::uint32_t>(std::stoul(cells[0], nullptr, 16));
    const exc::test::DbcMessage* message = nullptr;
    for (const auto& m : dbc) {
      if (m.id == id) message = &m;
    }
    CAPTURE(line);
    REQUIRE(message != nullptr);
    CHECK(cells[1] == message->name);
    if (cells.size() == 7) {  // frame table: ID, frame, sender, bytes, period, worst-case bits, worst-case time
      ++frame_rows;
      CHECK(cells[2] == message->sender);
      CHECK(std::stoi(cells[3]) == message->length);
      CHECK(cells[4] == (message->cycle_ms == 0 ? std::string("event") : std::to_string(message->cycle_ms) + " ms"));
      const exc::hal::CanFdFrameBits worst = exc::hal::canfd_frame_bits_worst(message->length);
      CHECK(cells[5] == std::to_string(worst.nominal) + " + " + std::to_string(worst.data));
      char time[32];
      std::snprintf(time, sizeof time, "%.1f us", static_cast<double>(worst.duration_ns()) / 1000.0);
      CHECK(cells[6] == time);
    } else {
      REQUIRE(cells.size() == 11);  // signal table
      ++signal_rows;
      const exc::test::DbcSignal* signal = nullptr;
      for (const auto& s : message->signals) {
        if (s.name == cells[2]) signal = &s;
      }
      REQUIRE(signal != nullptr);
      CHECK(std::stoi(cells[3]) == signal->start);
      CHECK(std::stoi(cells[4]) == signal->length);
      CHECK((cells[5] == "yes") == signal->is_signed);
      CHECK(std::stod(cells[6]) == doctest::Approx(signal->factor));
      CHECK(std::stod(cells[7]) == doctest::Approx(signal->offset));
      CHECK(std::stod(cells[8]) == doctest::Approx(signal->min));
      CHECK(std::stod(cells[9]) == doctest::Approx(signal->max));
      CHECK(cells[10] == (signal->unit.empty() ? std::string("-") : signal->unit));
    }
  }
  CHECK(frame_rows == dbc.size());
  CHECK(signal_rows == data_signals);
}
