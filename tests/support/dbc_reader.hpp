#pragma once
// A small reader for the parts of a DBC file the tests check against: BO_ (messages), SG_ (signals),
// the message attributes GenMsgCycleTime, GenMsgSendType, GenMsgCycleTimeFast, ExcCommandSet,
// VFrameFormat and CANFD_BRS, and the network's Baudrate and BaudrateCANFD. Written independently of
// hal/ so the test compares the codec's tables with the file, not with themselves.
#include <cstdint>
#include <fstream>
#include <map>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

namespace exc::test {

struct DbcSignal {
  std::string name;
  int start = 0;
  int length = 0;
  bool little_endian = true;
  bool is_signed = false;
  double factor = 1;
  double offset = 0;
  double min = 0;
  double max = 0;
  std::string unit;
};

struct DbcMessage {
  std::uint32_t id = 0;
  std::string name;
  int length = 0;  // payload bytes (BO_ size)
  std::string sender;
  std::vector<DbcSignal> signals;
  int cycle_ms = 0;
  bool if_active = false;  // GenMsgSendType IfActive: sent on entry, then every cycle_fast_ms while active
  int cycle_fast_ms = 0;
  int command_set = 0;  // index into ExcCommandSet's enum: 0 none, 1 effort, 2 valve, 3 pilot
  bool fd = false;       // VFrameFormat 14: StandardCAN_FD
  bool brs = false;      // CANFD_BRS 1
};

struct DbcNetwork {
  long baudrate = 0;        // BA_ "Baudrate": the nominal (arbitration) bit rate, bit/s
  long baudrate_canfd = 0;  // BA_ "BaudrateCANFD": the CAN FD data-phase bit rate, bit/s
};

inline std::vector<DbcMessage> read_dbc(const std::string& path, DbcNetwork* network = nullptr) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open DBC file " + path);
  const std::regex bo(R"(^BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+)\s+(\w+))");
  const std::regex sg(
      R"(^\s+SG_\s+(\w+)\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(([^,]+),([^)]+)\)\s*\[([^|]+)\|([^\]]+)\]\s*\"([^\"]*)\")");
  const std::regex ba(R"(^BA_\s+\"(\w+)\"\s+BO_\s+(\d+)\s+(\d+)\s*;)");
  const std::regex ba_network(R"(^BA_\s+\"(\w+)\"\s+(\d+)\s*;)");
  std::vector<DbcMessage> messages;
  std::map<std::uint32_t, std::size_t> by_id;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::smatch m;
    if (std::regex_search(line, m, bo)) {
      DbcMessage message;
      message.id = static_cast<std::uint32_t>(std::stoul(m[1]));
      message.name = m[2];
      message.length = std::stoi(m[3]);
      message.sender = m[4];
      by_id[message.id] = messages.size();
      messages.push_back(message);
    } else if (std::regex_search(line, m, sg)) {
      if (messages.empty()) throw std::runtime_error(path + ":" + std::to_string(line_number) + ": SG_ before BO_");
      DbcSignal s;
      s.name = m[1];
      s.start = std::stoi(m[2]);
      s.length = std::stoi(m[3]);
      s.little_endian = m[4] == "1";
      s.is_signed = m[5] == "-";
      s.factor = std::stod(m[6]);
      s.offset = std::stod(m[7]);
      s.min = std::stod(m[8]);
      s.max = std::stod(m[9]);
      s.unit = m[10];
      messages.back().signals.push_back(s);
    } else if (std::regex_search(line, m, ba)) {
      const auto it = by_id.find(static_cast<std::uint32_t>(std::stoul(m[2])));
      if (it == by_id.end()) throw std::runtime_error(path + ":" + std::to_string(line_number) + ": BA_ for unknown BO_");
      if (m[1] == "GenMsgCycleTime") messages[it->second].cycle_ms = std::stoi(m[3]);
      if (m[1] == "GenMsgCycleTimeFast") messages[it->second].cycle_fast_ms = std::stoi(m[3]);
      if (m[1] == "GenMsgSendType") messages[it->second].if_active = std::stoi(m[3]) == 1;
      if (m[1] == "ExcCommandSet") messages[it->second].command_set = std::stoi(m[3]);
      if (m[1] == "VFrameFormat") messages[it->second].fd = std::stoi(m[3]) == 14;
      if (m[1] == "CANFD_BRS") messages[it->second].brs = std::stoi(m[3]) == 1;
    } else if (std::regex_search(line, m, ba_network) && network != nullptr) {
      if (m[1] == "Baudrate") network->baudrate = std::stol(m[2]);
      if (m[1] == "BaudrateCANFD") network->baudrate_canfd = std::stol(m[2]);
    }
  }
  return messages;
}

// Raw field of a DBC signal, extracted bit by bit from the payload (Intel order), independently of
// the codec's 64-bit word arithmetic; then scaled as the DBC says.
inline std::uint64_t dbc_raw(const std::uint8_t* data, const DbcSignal& s) {
  std::uint64_t raw = 0;
  for (int i = 0; i < s.length; ++i) {
    const int bit = s.start + i;
    if ((data[bit / 8] >> (bit % 8)) & 1) raw |= std::uint64_t{1} << i;
  }
  return raw;
}

inline double dbc_physical(const std::uint8_t* data, const DbcSignal& s) {
  const std::uint64_t raw = dbc_raw(data, s);
  double value = static_cast<double>(raw);
  if (s.is_signed && s.length < 64 && (raw >> (s.length - 1)) != 0) value -= static_cast<double>(std::uint64_t{1} << s.length);
  return value * s.factor + s.offset;
}

}  // namespace exc::test
