// vcan-two-process-stand-in: minimal plant, firmware and in-process reference that speak the real
// protocol (hal ports over SocketCAN) with the command lines two_process.sh expects, so the harness
// itself (start order, kills, capture check, figure comparison) is tested before the real
// excavator-plant and excavator-firmware exist. No physics: the "plant" reports positions that are
// a fixed function of the cycle, the "firmware" accumulates their error against another function.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "app/float_environment.hpp"
#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/socketcan_bus.hpp"

using namespace exc::hal;

namespace {

constexpr std::int64_t kSilenceNs = 500'000'000;  // a side silent this long is gone (generous: hosts are loaded)
constexpr int kWatchdogCycles = 20;               // as the firmware's 20 ms watchdog at 1 kHz

double position_at(std::uint64_t cycle, int axis) { return 0.5 + 0.1 * axis + 0.01 * std::sin(0.003 * cycle + axis); }
double desired_at(std::uint64_t cycle, int axis) { return 0.5 + 0.1 * axis + 0.01 * std::sin(0.003 * cycle + axis + 0.01); }

struct Options {
  std::string role, interface_name = "vcan0", json;
  long cycles = 1000;
};

// The figures both the two-process run and the reference compute. Positions go through the CAN
// encoding in the two-process run, so the reference quantizes them the same way (SENS_MACHINE scaling).
struct Figures {
  double sum_sq[kAxisCount] = {};
  long samples = 0;
  long cycles = 0;  // SYNC frames sent (firmware) or cycles computed (reference)
  void add(const double* q, std::uint64_t cycle) {
    for (int j = 0; j < kAxisCount; ++j) {
      const double e = q[j] - desired_at(cycle, j);
      sum_sq[j] += e * e;
    }
    ++samples;
  }
  bool write(const std::string& path) const {
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    std::fprintf(f, "{\"cycles\": %ld, \"tracking\": {\"samples\": %ld, \"rms\": [", cycles, samples);
    for (int j = 0; j < kAxisCount; ++j)
      std::fprintf(f, "%s%.17g", j ? ", " : "", samples ? std::sqrt(sum_sq[j] / samples) : 0.0);
    // The loop thread's floating-point mode, as excavator-firmware reports it.
    std::fprintf(f, "]}, \"float_mode\": \"%s\"}\n", exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread()));
    return std::fclose(f) == 0;
  }
};

std::unique_ptr<SocketCanBus> open_bus(const Options& o, Node node) {
  std::uint32_t ids[kMessageCount];
  const std::size_t n = receive_ids(node, ids, kMessageCount);
  std::string error;
  auto bus = SocketCanBus::open(o.interface_name, ids, n, error);
  if (!bus) std::fprintf(stderr, "vcan-two-process-stand-in: %s\n", error.c_str());
  return bus;
}

int run_plant(const Options& o) {
  auto bus = open_bus(o, Node::plant);
  if (!bus) return 1;
  PlantCanPort port(*bus);
  long steps = 0;
  bool holding = false;
  std::int64_t last_sync = 0;
  while (steps < o.cycles) {
    std::uint64_t cycle = 0;
    if (port.wait_sync(cycle, 50'000'000)) {
      last_sync = monotonic_now_ns();
      SensorState s;
      s.cycle = cycle;
      for (int j = 0; j < kAxisCount; ++j) s.position[j] = position_at(cycle, j);
      port.write(s);
      CommandState c;
      port.read(c);
      ++steps;
      continue;
    }
    if (steps > 0 && monotonic_now_ns() - last_sync > kSilenceNs) {
      if (!holding) {
        std::printf("plant: no SYNC for %lld ms after %ld steps: holding\n", static_cast<long long>(kSilenceNs / 1'000'000), steps);
        std::fflush(stdout);
        holding = true;
      }
      port.send_fault(true, 1);
      last_sync = monotonic_now_ns();  // repeat the emergency once per silence period
    }
  }
  std::printf("plant: %ld steps; floating point: %s\n", steps,
              exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread()));
  return 0;
}

int run_firmware(const Options& o) {
  auto bus = open_bus(o, Node::firmware);
  if (!bus) return 1;
  FirmwareCanPort port(*bus);
  Figures figures;
  int missed = 0;
  bool safe_stop = false;
  for (long k = 0; k < o.cycles; ++k) {
    const auto cycle = static_cast<std::uint64_t>(k);
    port.send_sync(cycle);
    SensorState seen;
    bool complete = false;
    const std::int64_t deadline = monotonic_now_ns() + kSilenceNs;
    while (!(complete = port.read(seen)) && monotonic_now_ns() < deadline) bus->wait_readable(10'000'000);
    if (complete) {
      missed = 0;
      if (!safe_stop) figures.add(seen.position.data(), cycle);
    } else if (++missed >= kWatchdogCycles && !safe_stop) {
      safe_stop = true;
      std::printf("firmware: watchdog: no sensor frames for %d cycles: safe stop at cycle %ld\n", kWatchdogCycles, k);
      std::fflush(stdout);
    }
    if (safe_stop) {
      if (missed % kEmergencyRepeatCycles == kWatchdogCycles % kEmergencyRepeatCycles) port.send_fault(true, 1);
      continue;
    }
    CommandState c;
    c.cycle = cycle;
    port.write(c);
  }
  figures.cycles = o.cycles;
  if (!o.json.empty() && !figures.write(o.json)) return 1;
  return safe_stop ? 3 : 0;
}

int run_reference(const Options& o) {
  Figures figures;
  for (long k = 0; k < o.cycles; ++k) {
    double q[kAxisCount];
    for (int j = 0; j < kAxisCount; ++j) {
      // The SENS_MACHINE position signal's quantization, as the frame carries it.
      static constexpr const char* kPositionSignal[kAxisCount] = {"SwingAngle", "BoomLength", "ArmLength", "BucketLength"};
      CanFrame frame;
      const MessageSpec& spec = *find_message(can_id::sens_machine);
      std::size_t i = 0;
      while (i + 1 < spec.data_signal_count() && std::strcmp(spec.data_signal(i).name, kPositionSignal[j]) != 0) ++i;
      encode_signal(frame, spec.data_signal(i), position_at(static_cast<std::uint64_t>(k), j));
      q[j] = decode_signal(frame, spec.data_signal(i));
    }
    figures.add(q, static_cast<std::uint64_t>(k));
  }
  figures.cycles = o.cycles;
  return (!o.json.empty() && !figures.write(o.json)) ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  exc::app::set_loop_float_mode();  // as excavator-plant and excavator-firmware do
  Options o;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0) {
    std::puts(
        "Usage: vcan-two-process-stand-in plant|firmware|reference [--can IFACE] [--duration S] [--json FILE]\n"
        "Test stand-ins for excavator-plant, excavator-firmware and the in-process run (see\n"
        "tests/vcan/two_process.sh); other options of the real programs are accepted and ignored.");
    return argc < 2 ? 2 : 0;
  }
  o.role = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--can" && has_value) {
      o.interface_name = argv[++i];
    } else if (a == "--duration" && has_value) {
      const double s = std::atof(argv[++i]);
      if (!(s > 0 && s <= 3600)) {
        std::fprintf(stderr, "vcan-two-process-stand-in: --duration '%s': must be seconds in (0, 3600]\n", argv[i]);
        return 2;
      }
      o.cycles = std::lround(s * 1000);
    } else if (a == "--json" && has_value) {
      o.json = argv[++i];
    }
  }
  if (o.role == "plant") return run_plant(o);
  if (o.role == "firmware") return run_firmware(o);
  if (o.role == "reference") return run_reference(o);
  std::fprintf(stderr, "vcan-two-process-stand-in: unknown role '%s' (plant, firmware or reference)\n", o.role.c_str());
  return 2;
}
