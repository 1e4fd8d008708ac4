#include "harness/target_firmware.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "harness/image_footprint.hpp"

namespace exc::sim {
namespace {

constexpr std::size_t kSettingsChunkBytes = 4000;  // under the image's 4 KiB record limit

std::uint8_t type_of(app::PilRecord r) { return static_cast<std::uint8_t>(r); }

// The exact order statistic of a sample (the q-quantile, nearest rank).
std::uint64_t rank(std::vector<std::uint32_t>& v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

std::string firmware_target_image(const std::string& target) {
  if (target != "cortex-m7") throw std::invalid_argument("--firmware-target " + target + ": the one target is cortex-m7");
  if (const char* image = std::getenv("EXC_FIRMWARE_IMAGE"); image != nullptr && *image != 0) return image;
#ifdef EXC_FIRMWARE_IMAGE_PATH
  return EXC_FIRMWARE_IMAGE_PATH;
#else
  return "";
#endif
}

TargetFirmware::TargetFirmware(const std::string& image, const app::FirmwareImageSettings& settings, hal::CanBus& bus,
                               telemetry::TelemetrySink* telemetry, double timeout_s)
    : target_(EmulatedTargetOptions{image, {}, timeout_s}), bus_(bus), telemetry_(telemetry) {
  const std::vector<std::uint8_t> blob = app::encode_settings_blob(settings);
  for (std::size_t at = 0; at < blob.size(); at += kSettingsChunkBytes)
    target_.send(type_of(app::PilRecord::settings_chunk), blob.data() + at, std::min(kSettingsChunkBytes, blob.size() - at));
  target_.send(type_of(app::PilRecord::settings_chunk), nullptr, 0);  // the end
  target_.flush();
  const std::vector<TargetRecord> answer = target_.receive_until(type_of(app::PilRecord::ready), type_of(app::PilRecord::refused));
  if (answer.back().type == type_of(app::PilRecord::refused))
    throw EmulatedTargetError("the firmware image " + image + " refused the settings of scene " + settings.scene + ": " +
                              std::string(answer.back().payload.begin(), answer.back().payload.end()));
  const std::size_t cycles = static_cast<std::size_t>(std::max<std::int64_t>(0, settings.cycles));
  for (auto& v : instructions_) v.reserve(cycles + 1);
}

TargetFirmware::~TargetFirmware() = default;

const TargetRecord& TargetFirmware::forward(const std::vector<TargetRecord>& records) {
  for (const TargetRecord& r : records) {
    if (r.type == type_of(app::PilRecord::frame_out)) {
      hal::CanFrame f;
      if (!app::decode_frame(r.payload.data(), r.payload.size(), f))
        throw EmulatedTargetError("the firmware image " + target_.image() + " sent a CAN frame record that does not decode");
      bus_.send(f);  // as the node's port would: a frame the bus refuses is the bus's to count
    } else if (r.type == type_of(app::PilRecord::telemetry) && telemetry_ != nullptr && r.payload.size() > 1) {
      std::vector<std::uint8_t> bytes(r.payload.begin() + 1, r.payload.end());
      telemetry_->publish_encoded(static_cast<telemetry::Channel>(r.payload[0]), bytes.data(), bytes.size());
    }
  }
  return records.back();
}

void TargetFirmware::begin_cycle() {
  target_.send(type_of(app::PilRecord::begin), nullptr, 0);
  target_.flush();
  forward(target_.receive_until(type_of(app::PilRecord::awaiting_inputs)));
}

void TargetFirmware::end_cycle() {
  // The bus's frames for the firmware: the plant's answer, an operator station's frames.
  std::uint8_t payload[app::kFrameRecordMaxBytes];
  for (hal::CanFrame f; bus_.receive(f);) target_.send(type_of(app::PilRecord::frame_in), payload, app::encode_frame(f, payload, sizeof payload));
  target_.send(type_of(app::PilRecord::inputs_done), nullptr, 0);
  target_.flush();
  const std::vector<TargetRecord> records = target_.receive_until(type_of(app::PilRecord::cycle_done));
  const TargetRecord& done = forward(records);
  if (!app::decode_status(done.payload.data(), done.payload.size(), status_))
    throw EmulatedTargetError("the firmware image " + target_.image() + " sent a cycle status that does not decode");
  const bool commanded = status_.instructions[2] != 0 || status_.instructions[3] != 0;
  for (int s = 0; s < app::kTargetStages; ++s)
    if (commanded || (s != 2 && s != 3 && s != 4 && s != 5)) instructions_[s].push_back(status_.instructions[s]);
}

app::RunSummaryRecord TargetFirmware::finish() {
  if (finished_) throw std::logic_error("TargetFirmware::finish called twice");
  finished_ = true;
  // The image waits for its next cycle: the run's end instead.
  target_.send(type_of(app::PilRecord::run_end), nullptr, 0);
  target_.send(type_of(app::PilRecord::begin), nullptr, 0);
  target_.flush();
  const std::vector<TargetRecord> records = target_.receive_until(type_of(app::PilRecord::summary));
  const TargetRecord& last = forward(records);
  app::RunSummaryRecord summary;
  if (!app::decode_summary(last.payload.data(), last.payload.size(), summary))
    throw EmulatedTargetError("the firmware image " + target_.image() + " sent a run summary that does not decode");
  const int status = target_.wait_for_exit();
  if (status != 0)
    throw EmulatedTargetError("the firmware image " + target_.image() + " exited with status " + std::to_string(status) +
                              " after its run: " + target_.printed_stderr());

  TargetFigures f;
  f.image = target_.image();
  const std::vector<std::uint32_t>& whole = instructions_[app::kTargetStages - 1];
  f.worst_cycle = whole.empty() ? 0 : static_cast<std::uint64_t>(std::max_element(whole.begin(), whole.end()) - whole.begin()) + 1;
  for (int s = 0; s < app::kTargetStages; ++s) {
    std::vector<std::uint32_t>& v = instructions_[s];
    InstructionFigures& x = f.stages[static_cast<std::size_t>(s)];
    x.cycles = v.size();
    x.max = v.empty() ? 0 : *std::max_element(v.begin(), v.end());
    x.median = rank(v, 0.5);
    x.p99 = rank(v, 0.99);
  }
  const ImageFootprint footprint = read_image_footprint(target_.image());
  f.flash_bytes = footprint.flash_bytes;
  // RAM: the program's own variables, what start-up took of the heap, and the stack it reserves.
  f.ram_bytes = footprint.ram_static_bytes + summary.heap_bytes_used + footprint.stack_bytes;
  f.stack_size_bytes = footprint.stack_bytes;
  f.stack_bytes = summary.stack_bytes_used;
  f.heap_calls_after_start_up = summary.heap_calls_after_start_up;
  f.start_up_instructions = summary.start_up_instructions;
  figures_ = f;
  return summary;
}

}  // namespace exc::sim
