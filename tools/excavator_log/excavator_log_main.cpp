// excavator-log: reads LCM logs of the excavator's telemetry (lcm-logger's or the firmware's own
// file:// provider output) with LCM's log reader.
//   excavator-log info run.lcm            channels, types, counts, duration
//   excavator-log export run.lcm --csv DIR [--summary JSON]  one CSV per channel (a long one: its
//                                           bucketed view, and detail rows around the summary's worst moments)
//   excavator-log report run.lcm --out DIR [--summary JSON]  CSV, then plot-run's figures and report
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "log_export/log_export.hpp"
#include "summary_moments.hpp"
#include "output_files/output_file.hpp"
#include "output_files/helper_program.hpp"
#include "option_checks.hpp"

namespace {

// A log with bytes in no complete event (cut short or damaged) is read up to them; said on stderr.
void warn_unread(const std::string& log_path, const exc::log::LogSummary& summary) {
  if (summary.unread_bytes == 0) return;
  std::fprintf(stderr,
               "excavator-log: warning: %s: %llu bytes are in no complete event (a log cut short or damaged); "
               "the %llu complete events are used\n",
               log_path.c_str(), static_cast<unsigned long long>(summary.unread_bytes),
               static_cast<unsigned long long>(summary.events));
}

void print_summary(const std::string& log_path, const exc::log::LogSummary& summary) {
  // Rates are per second of the run (the messages' own utime): a simulated run is logged far faster
  // than real time, so the log's wall-clock stamps would give a 1 kHz channel 100 kHz or more.
  bool any_decoded = false;
  std::int64_t run_first = 0, run_last = 0;
  for (const auto& [name, channel] : summary.channels) {
    if (channel.messages == channel.undecodable || channel.type_name == "unknown") continue;
    run_first = any_decoded ? std::min(run_first, channel.min_utime) : channel.min_utime;
    run_last = any_decoded ? std::max(run_last, channel.max_utime) : channel.max_utime;
    any_decoded = true;
  }
  std::printf("%s: %llu events", log_path.c_str(), static_cast<unsigned long long>(summary.events));
  if (any_decoded) std::printf(", run time %.3f to %.3f s (the messages' utime)", run_first * 1e-6, run_last * 1e-6);
  std::printf(", logged in %.3f s of wall time\n", summary.duration_s());
  std::printf("%-32s %-20s %10s %10s %10s\n", "channel", "type", "messages", "rate_hz", "undecodable");
  for (const auto& [name, channel] : summary.channels) {
    const std::uint64_t decoded = channel.messages - channel.undecodable;
    const double span = (static_cast<double>(channel.max_utime) - static_cast<double>(channel.min_utime)) * 1e-6;
    char rate[32] = "-";  // no decoded message with a time, or all at one instant
    if (channel.type_name != "unknown" && decoded > 1 && span > 0)
      std::snprintf(rate, sizeof rate, "%.1f", static_cast<double>(decoded - 1) / span);
    std::printf("%-32s %-20s %10llu %10s %10llu\n", exc::log::printable_channel(name).c_str(), channel.type_name.c_str(),
                static_cast<unsigned long long>(channel.messages), rate,
                static_cast<unsigned long long>(channel.undecodable));
  }
}

// Messages a channel's sequence numbers say were published but are not in the log.
void print_gaps(const exc::log::LogSummary& summary) {
  for (const auto& [name, channel] : summary.channels) {
    if (channel.seq_gaps == 0) continue;
    const std::int64_t span = channel.last_seq - channel.first_seq + 1;
    std::printf("%s: %llu of %lld messages missing (sequence numbers %lld to %lld, %llu gap%s): published but not "
                "recorded, e.g. dropped by a logger over UDP\n",
                exc::log::printable_channel(name).c_str(), static_cast<unsigned long long>(channel.seq_missing),
                static_cast<long long>(span), static_cast<long long>(channel.first_seq),
                static_cast<long long>(channel.last_seq), static_cast<unsigned long long>(channel.seq_gaps),
                channel.seq_gaps == 1 ? "" : "s");
  }
}

// Exit status of a failed read: 2 for bad input (as every program here), 1 for a failed write.
int failure(const exc::log::LogSummary& summary, const std::string& error) {
  std::fprintf(stderr, "excavator-log: %s\n", error.c_str());
  return summary.bad_input ? 2 : 1;
}

// plot-run: the one built next to this program (build tree), else the one on PATH (installed).
std::string plot_run_program() {
#ifdef EXC_PLOT_RUN
  if (std::filesystem::exists(EXC_PLOT_RUN)) return EXC_PLOT_RUN;
#endif
  return "plot-run";
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-log");  // stdout lost to a full disk is not exit 0
  CLI::App app{"excavator-log: summarise LCM telemetry logs and export them to CSV"};
  app.require_subcommand(1);

  std::string info_log;
  CLI::App* info = app.add_subcommand("info", "List the channels of a log: type, count, rate");
  info->add_option("log", info_log, "LCM log file (lcm-logger or file:// provider output)")
      ->required();

  std::string export_log;
  std::string csv_dir;
  exc::log::ExportOptions options;
  CLI::App* exporter = app.add_subcommand(
      "export", "Write every channel of known exlcm type to DIR/<channel>.csv ('/' -> '__'), "
                "with a header row, doubles at 17 significant digits; a channel of more than "
                "--full-rows messages as its bucketed view, one of more than --bucket-rows with its "
                "bucketed view in DIR/buckets too; both with their detail rows in DIR/detail");
  exporter->add_option("log", export_log, "LCM log file")->required();
  exporter->add_option("--csv", csv_dir, "Output directory for the CSV files (created)")
      ->required();
  std::string export_summary;
  exporter->add_option("--summary", export_summary,
                       "The run's summary JSON (excavator-sim's): a long channel's detail rows also cover the "
                       "moment of each phase's worst error per joint it names (the plant's truth)")
      ->check(CLI::ExistingFile);

  std::string report_log;
  std::string report_dir;
  std::string summary_json;
  std::string title = "Excavator run report";
  CLI::App* reporter = app.add_subcommand(
      "report", "Export the log to DIR/csv, then draw the figures and DIR/report.md with plot-run");
  reporter->add_option("log", report_log, "LCM log file")->required();
  reporter->add_option("--out", report_dir, "Output directory (csv/ and the report)")->required();
  reporter->add_option("--summary", summary_json, "JSON summary table to include in the report")
      ->check(CLI::ExistingFile);
  reporter->add_option("--title", title, "Report title");
  for (CLI::App* sub : {exporter, reporter}) {
    sub->add_option("--full-rows", options.full_rows, "Most messages a channel is written one row each")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--bucket-rows", options.bucket_rows,
                    "More messages than this: the channel's bucketed view (buckets/) and detail rows (detail/) too")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    sub->add_option("--buckets", options.buckets, "Time buckets of a long channel's bucketed view")
        ->capture_default_str()
        ->check(CLI::Range(10, 100000));
  }

  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  // The summary's worst moments: the report's zoom on each phase's worst error needs their rows.
  if (const std::string& json = reporter->parsed() ? summary_json : export_summary; !json.empty()) {
    std::string error;
    if (!exc::log::read_summary_moments(json, &options.detail_moments, &error)) {
      std::fprintf(stderr, "excavator-log: %s\n", error.c_str());
      return 2;
    }
  }

  exc::log::LogSummary summary;
  std::string error;
  if (info->parsed()) {
    if (!exc::log::summarize_log(info_log, &summary, &error)) return failure(summary, error);
    print_summary(info_log, summary);
    print_gaps(summary);
    warn_unread(info_log, summary);
    return 0;
  }
  if (reporter->parsed()) {
    const std::string csv = (std::filesystem::path(report_dir) / "csv").string();
    if (!exc::log::export_log_to_csv(report_log, csv, &summary, &error, options)) return failure(summary, error);
    warn_unread(report_log, summary);
    std::vector<std::string> command = {plot_run_program(), csv, "--out", report_dir, "--title", title};
    if (!summary_json.empty()) command.insert(command.end(), {"--summary", summary_json});
    if (exc::output::run_helper(command) != 0) {
      std::fprintf(stderr, "excavator-log: plot-run failed (%s)\n", exc::output::command_text(command).c_str());
      return 1;
    }
    return 0;
  }
  if (!exc::log::export_log_to_csv(export_log, csv_dir, &summary, &error, options)) return failure(summary, error);
  print_summary(export_log, summary);
  print_gaps(summary);
  warn_unread(export_log, summary);
  for (const auto& [name, channel] : summary.channels) {
    if (channel.type_name == "unknown") {
      std::fprintf(stderr, "excavator-log: channel %s is not an exlcm type: not exported\n",
                   exc::log::printable_channel(name).c_str());
    }
    if (!channel.csv_file.empty() && channel.csv_file != exc::log::csv_file_name(name)) {
      std::printf("%s: written to %s (another channel's name maps to %s)\n", exc::log::printable_channel(name).c_str(),
                  channel.csv_file.c_str(), exc::log::csv_file_name(name).c_str());
    }
    if (channel.bucketed) {
      std::printf("%s: %llu messages: %s as %d time buckets (first, last, min, max, sums), detail rows "
                  "in detail/\n", exc::log::printable_channel(name).c_str(), static_cast<unsigned long long>(channel.messages),
                  channel.rows_written ? "one row each, and in buckets/" : "written", options.buckets);
    }
  }
  std::printf("CSV files written to %s\n", csv_dir.c_str());
  return 0;
}
