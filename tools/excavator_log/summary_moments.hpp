#pragma once
// The moments a run's summary names as each controller's worst error per joint and phase
// (excavator-sim's summary: <controller>.phases.<phase>.worst_time.<joint>, s of the run, from the
// plant's truth), for the export's detail rows around them: the report's zoom on each phase's worst
// error then has the logged rows of that moment.
#include <map>
#include <string>
#include <vector>

namespace exc::log {

// By controller (the name the summary keys its run by, as the channels' suffix), the moments in s.
// A JSON without such runs (any other summary plot-run can tabulate) names none. False and `error`
// (the file and the field) for a file that cannot be read, is not JSON, or names a worst_time that is
// not a number of seconds (-1, a phase without samples, is skipped).
bool read_summary_moments(const std::string& path, std::map<std::string, std::vector<double>>* moments,
                          std::string* error);

}  // namespace exc::log
