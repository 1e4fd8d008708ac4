#include "capture_check.hpp"

#include <cstdio>

#include "hal/can_codec.hpp"
#include "hal/can_protocol.hpp"
#include "candump_log.hpp"

namespace exc::vcan {

namespace {

std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%03X", v);
  return buf;
}

std::string decoded_signals(const exc::hal::MessageSpec& spec, const exc::hal::CanFrame& frame) {
  double values[exc::hal::kMaxDataSignals] = {};
  exc::hal::decode_message(spec, frame, values);
  std::string text;
  for (std::size_t i = 0; i < spec.data_signal_count(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s=%g", text.empty() ? "" : " ", spec.data_signal(i).name, values[i]);
    text += buf;
  }
  return text;
}

struct Accepted {
  std::size_t line;
  exc::hal::CanFrame frame;
  const exc::hal::MessageSpec* spec;
};

}  // namespace

CaptureReport check_capture(std::istream& in, const std::string& interface_name) {
  using namespace exc::hal;
  using exc::test::CandumpLine;
  using exc::test::parse_candump_line;
  CaptureReport report;
  bool have_sync = false;
  std::uint8_t sync_counter = 0;
  std::map<std::uint32_t, int> own_counter;  // last counter per non-cyclic ID
  std::vector<Accepted> accepted;
  std::string text;
  std::size_t line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    ++report.frames;
    const std::string where = "line " + std::to_string(line_no) + ": ";
    CandumpLine line;
    std::string error;
    if (!parse_candump_line(text, line, error)) {
      report.errors.push_back(where + "not a candump -L line (" + error + ")");
      continue;
    }
    if (!interface_name.empty() && line.interface_name != interface_name) {
      report.errors.push_back(where + "interface " + line.interface_name + ", expected " + interface_name);
      continue;
    }
    if (line.extended || line.remote) {
      report.errors.push_back(where + "not an 11-bit data frame");
      continue;
    }
    const CanFrame& frame = line.frame;
    const MessageSpec* spec = find_message(frame.id);
    if (spec == nullptr) {
      report.errors.push_back(where + "identifier " + hex(frame.id) + " is not in the DBC");
      continue;
    }
    if (frame.fd != spec->fd || frame.brs != spec->brs) {
      const auto format = [](bool fd, bool brs) {
        return std::string(fd ? (brs ? "CAN FD with bit-rate switch" : "CAN FD without bit-rate switch") : "classical CAN");
      };
      report.errors.push_back(where + spec->name + " is " + format(frame.fd, frame.brs) + ", the DBC says " +
                              format(spec->fd, spec->brs));
      continue;
    }
    if (frame.len != spec->length) {
      report.errors.push_back(where + spec->name + " has " + std::to_string(frame.len) + " bytes, the DBC says " +
                              std::to_string(spec->length));
      continue;
    }
    const std::uint8_t crc = frame_checksum(frame.id, frame.data, static_cast<std::size_t>(frame.len - 1));
    if (crc != frame.data[frame.len - 1]) {
      report.errors.push_back(where + spec->name + " checksum " + hex(frame.data[frame.len - 1]) + ", expected " + hex(crc));
      continue;
    }
    const std::uint8_t counter = frame_counter(frame);
    if (frame.id == can_id::sync) {
      if (have_sync && counter != ((sync_counter + 1) & 0x0F)) {
        report.errors.push_back(where + "SYNC counter " + std::to_string(counter) + " after " +
                                std::to_string(sync_counter) + " (a cycle was skipped or repeated)");
      }
      have_sync = true;
      sync_counter = counter;
      ++report.syncs;
    } else if (spec->cycle_ms == 1) {
      if (!have_sync) {
        report.errors.push_back(where + spec->name + " before the first SYNC");
      } else if (counter != sync_counter) {
        report.errors.push_back(where + spec->name + " counter " + std::to_string(counter) +
                                " does not match the last SYNC's " + std::to_string(sync_counter));
      }
    } else {
      auto it = own_counter.find(frame.id);
      if (it != own_counter.end() && counter != ((it->second + 1) & 0x0F)) {
        report.errors.push_back(where + spec->name + " counter " + std::to_string(counter) + " after " +
                                std::to_string(it->second) + " (a frame was lost or repeated)");
      }
      own_counter[frame.id] = counter;
    }
    ++report.per_message[spec->name];
    accepted.push_back({line_no, frame, spec});
  }
  if (report.frames == 0) report.errors.push_back("the capture has no frames");

  // Reactions to silence: the last ordinary frame of each side, then the other side's emergency.
  std::size_t last_plant = accepted.size(), last_firmware = accepted.size();
  for (std::size_t i = 0; i < accepted.size(); ++i) {
    const std::uint32_t id = accepted[i].frame.id;
    // An operator station's frames are neither side's.
    if (id == can_id::fw_emergency || id == can_id::plant_emergency || id == can_id::supervisor) continue;
    (accepted[i].spec->sender == Node::plant ? last_plant : last_firmware) = i;
  }
  if (last_plant < accepted.size()) {
    report.last_plant_line = accepted[last_plant].line;
    long syncs = 0;
    for (std::size_t i = last_plant + 1; i < accepted.size(); ++i) {
      if (accepted[i].frame.id == can_id::sync) ++syncs;
      if (accepted[i].frame.id == can_id::fw_emergency) {
        report.fw_emergency_line = accepted[i].line;
        report.fw_emergency_cycles = syncs;
        report.fw_emergency_signals = decoded_signals(*accepted[i].spec, accepted[i].frame);
        break;
      }
    }
  }
  if (last_firmware < accepted.size()) {
    report.last_firmware_line = accepted[last_firmware].line;
    for (std::size_t i = last_firmware + 1; i < accepted.size(); ++i) {
      if (accepted[i].frame.id == can_id::plant_emergency) {
        report.plant_emergency_line = accepted[i].line;
        report.plant_emergency_signals = decoded_signals(*accepted[i].spec, accepted[i].frame);
        break;
      }
    }
  }
  return report;
}

}  // namespace exc::vcan
