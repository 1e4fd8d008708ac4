#include "callgrind_split.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <string>

extern char** environ;

namespace exc::bench {
namespace {

// The run_lockstep that runs the loop, from the node's settings (the other builds those and calls it:
// a toggle matching both would switch collection off inside the loop).
constexpr const char* kLoopFunction = "exc::sim::run_lockstep(exc::plant::Scene const&, exc::app::FirmwareImageSettings const&";

}  // namespace

const std::vector<Stage>& loop_stages() {
  static const std::vector<Stage> s = {
      {"the loop (run_lockstep, start-up included)", 0, {kLoopFunction}},
      {"firmware: SYNC and heartbeat (FirmwareNode::begin_cycle)", 1, {"exc::app::FirmwareNode::begin_cycle()"}},
      {"plant node (PlantNode::poll)", 1, {"exc::plant::PlantNode::poll()"}},
      {"CAN read: SYNC and command (PlantCanPort::poll_sync)", 2, {"exc::hal::PlantCanPort::poll_sync("}},
      {"Plant::step (dynamics, hydraulics, soil, checks, sensors)", 2, {"exc::plant::Plant::step("}},
      {"forward dynamics (Integrator::evaluate_independent)", 3, {"exc::plant::Integrator::evaluate_independent("}},
      {"hydraulic circuit (HydraulicCircuit::advance)", 3, {"exc::plant::HydraulicCircuit::advance("}},
      {"CAN write: SENS_MACHINE (PlantCanPort::write)", 2, {"exc::hal::PlantCanPort::write("}},
      {"telemetry encode (PlantNode::publish_state)", 2, {"exc::plant::PlantNode::publish_state()"}},
      {"firmware node (FirmwareNode::end_cycle)", 1, {"exc::app::FirmwareNode::end_cycle()"}},
      {"CAN read: SENS_MACHINE (FirmwareCanPort::read)", 2, {"exc::hal::FirmwareCanPort::read("}},
      {"control (FirmwareNode::compute_command)", 2, {"exc::app::FirmwareNode::compute_command("}},
      {"control law (Controller::update)", 3, {"::update(exc::control::ControlInput const&)"}},
      {"valve stage (ValveInnerLoop::from_force, from_velocity)", 3,
       {"exc::control::ValveInnerLoop::from_force(", "exc::control::ValveInnerLoop::from_velocity("}},
      {"CAN write: CMD_PILOT (FirmwareCanPort::write)", 2, {"exc::hal::FirmwareCanPort::write("}},
      {"telemetry encode (publish_cycle, publish_counters)", 2,
       {"exc::app::FirmwareNode::publish_cycle(", "exc::app::FirmwareNode::publish_counters("}},
      {"across the nodes: exact on-wire frame time (frame_time_ns)", 0, {"exc::hal::frame_time_ns("}},
      {"across the nodes: frame encode (encode_message)", 0, {"exc::hal::encode_message("}},
      {"across the nodes: frame validate and decode (accept, decode_message)", 0,
       {"exc::hal::CanFrameCodec::accept(", "exc::hal::decode_message("}},
      {"across the nodes: the model evaluations (update_closed_chain, mass_matrix, bias_forces)", 0,
       {"exc::update_closed_chain(", "exc::mass_matrix(", "exc::bias_forces("}},
      {"telemetry thread: LCM log writes (TelemetryPublisher::run)", 0, {"exc::telemetry::TelemetryPublisher::run()"}},
  };
  return s;
}

const std::vector<std::string>& loop_toggles() {
  // Counted only inside the loop and the telemetry thread: the model functions also run while the
  // scene loads (the effort-feasibility check), which is not a cycle's cost.
  static const std::vector<std::string> t = {std::string(kLoopFunction) + "*", "exc::telemetry::TelemetryPublisher::run*"};
  return t;
}

const std::vector<Stage>& model_evaluation_stages() {
  static const std::vector<Stage> s = {
      {"the firmware's (passive angles skipped), planar path", 0, {"exc::bench::firmware_evaluations_planar("}},
      {"the firmware's, general path (the code before)", 0, {"exc::bench::firmware_evaluations_general("}},
      {"the plant's (with the 8 passive angles), planar path", 0, {"exc::bench::plant_evaluations_planar("}},
      {"the plant's, general path (the code before)", 0, {"exc::bench::plant_evaluations_general("}},
  };
  return s;
}

const std::vector<std::string>& model_evaluation_toggles() {
  static const std::vector<std::string> t = {"exc::bench::*_evaluations_*"};
  return t;
}

namespace {

bool run(const std::vector<std::string>& argv) {
  std::vector<char*> raw;
  for (const std::string& a : argv) raw.push_back(const_cast<char*>(a.c_str()));
  raw.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, raw[0], nullptr, nullptr, raw.data(), environ) != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// "1,234,567 (12.34%)  file:function [object]" -> 1234567, or -1 for any other line.
double leading_count(const std::string& line) {
  std::string digits;
  std::size_t i = line.find_first_not_of(' ');
  if (i == std::string::npos) return -1;
  for (; i < line.size() && (std::isdigit(static_cast<unsigned char>(line[i])) || line[i] == ','); ++i)
    if (line[i] != ',') digits += line[i];
  return digits.empty() ? -1 : std::strtod(digits.c_str(), nullptr);
}

}  // namespace

std::vector<StageCount> callgrind_split(const std::string& program, const std::vector<std::string>& args, double cycles,
                                        const std::vector<Stage>& stages, const std::vector<std::string>& toggles,
                                        std::string& why) {
  std::vector<StageCount> out;
  char dir[] = "/tmp/loop-bench-XXXXXX";
  if (mkdtemp(dir) == nullptr) return why = "no temporary directory", out;
  const std::string profile = std::string(dir) + "/callgrind.out", stripped = std::string(dir) + "/child";
  // Without debug information: with it callgrind splits a function by the source file of each inlined
  // piece (Eigen's headers), and the inclusive counts of the pieces no longer add up.
  const bool copied = run({"objcopy", "--strip-debug", program, stripped});
  std::vector<std::string> argv = {"valgrind", "-q", "--tool=callgrind", "--callgrind-out-file=" + profile};
  for (const std::string& t : toggles) argv.push_back("--toggle-collect=" + t);
  argv.push_back(copied ? stripped : program);
  argv.insert(argv.end(), args.begin(), args.end());
  if (!run(argv)) {
    std::remove(stripped.c_str());
    rmdir(dir);
    why = "valgrind --tool=callgrind did not run the child (is valgrind installed?)";
    return out;
  }
  const std::string annotate = "callgrind_annotate --inclusive=yes --threshold=100 " + profile + " 2>/dev/null";
  FILE* pipe = popen(annotate.c_str(), "r");
  if (pipe == nullptr) return why = "callgrind_annotate did not run", out;
  std::vector<double> sums(stages.size(), 0.0);
  std::vector<bool> seen(stages.size(), false);
  char buffer[8192];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) {
    const std::string line(buffer);
    const double count = leading_count(line);
    if (count < 0) continue;
    for (std::size_t s = 0; s < stages.size(); ++s) {
      for (const char* f : stages[s].functions) {
        if (line.find(f) == std::string::npos) continue;
        sums[s] += count;
        seen[s] = true;
      }
    }
  }
  const bool annotated = pclose(pipe) == 0;
  std::remove(profile.c_str());
  std::remove(stripped.c_str());
  rmdir(dir);
  if (!annotated || !seen[0]) return why = std::string("callgrind_annotate gave no count of ") + stages[0].functions[0], out;
  for (std::size_t s = 0; s < stages.size(); ++s)
    out.push_back(StageCount{stages[s].label, stages[s].depth, seen[s] ? sums[s] / cycles : -1});
  return out;
}

}  // namespace exc::bench
