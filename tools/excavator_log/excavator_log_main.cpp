// excavator-log: reads LCM logs of the excavator's telemetry (lcm-logger's or the firmware's own
// file:// provider output) with LCM's log reader.
//   excavator-log info run.lcm            channels, types, counts, duration
//   excavator-log export run.lcm --csv DIR  one CSV per channel
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

#include "log_export.hpp"

namespace {

void print_summary(const std::string& log_path, const exc::log::LogSummary& summary) {
  std::printf("%s: %llu events over %.3f s\n", log_path.c_str(),
              static_cast<unsigned long long>(summary.events), summary.duration_s());
  std::printf("%-32s %-20s %10s %10s %10s\n", "channel", "type", "messages", "rate_hz",
              "undecodable");
  for (const auto& [name, channel] : summary.channels) {
    const double span = (channel.last_log_utime - channel.first_log_utime) * 1e-6;
    const double rate = span > 0 ? (channel.messages - 1) / span : 0.0;
    std::printf("%-32s %-20s %10llu %10.1f %10llu\n", name.c_str(), channel.type_name.c_str(),
                static_cast<unsigned long long>(channel.messages), rate,
                static_cast<unsigned long long>(channel.undecodable));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"excavator-log: summarise LCM telemetry logs and export them to CSV"};
  app.require_subcommand(1);

  std::string info_log;
  CLI::App* info = app.add_subcommand("info", "List the channels of a log: type, count, rate");
  info->add_option("log", info_log, "LCM log file (lcm-logger or file:// provider output)")
      ->required();

  std::string export_log;
  std::string csv_dir;
  CLI::App* exporter = app.add_subcommand(
      "export", "Write every channel of known exlcm type to DIR/<channel>.csv ('/' -> '__'), "
                "with a header row, doubles at 17 significant digits");
  exporter->add_option("log", export_log, "LCM log file")->required();
  exporter->add_option("--csv", csv_dir, "Output directory for the CSV files (created)")
      ->required();

  CLI11_PARSE(app, argc, argv);

  exc::log::LogSummary summary;
  std::string error;
  if (info->parsed()) {
    if (!exc::log::summarize_log(info_log, &summary, &error)) {
      std::fprintf(stderr, "excavator-log: %s\n", error.c_str());
      return 1;
    }
    print_summary(info_log, summary);
    return 0;
  }
  if (!exc::log::export_log_to_csv(export_log, csv_dir, &summary, &error)) {
    std::fprintf(stderr, "excavator-log: %s\n", error.c_str());
    return 1;
  }
  print_summary(export_log, summary);
  for (const auto& [name, channel] : summary.channels) {
    if (channel.type_name == "unknown") {
      std::fprintf(stderr, "excavator-log: channel %s is not an exlcm type: not exported\n",
                   name.c_str());
    }
  }
  std::printf("CSV files written to %s\n", csv_dir.c_str());
  return 0;
}
