// excavator-plant-bench: the plant's figures (README "Plant figures"). Build without EXC_TEST_BUILD
// (Release) for meaningful times.
#include <algorithm>
#include <bitset>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "option_checks.hpp"

#include "app/float_environment.hpp"
#include "bench/plant_drivers.hpp"
#include "output_files/output_file.hpp"
#include "sim_plant/integration_methods.hpp"
#include "sim_plant/plant.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::plant;
using Clock = std::chrono::steady_clock;

using bench::Stats;
using bench::TaskDriver;
using bench::ValveDriver;
using bench::stable_in_stiff_clay;
using bench::stats;


int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-plant-bench");  // stdout lost to a full disk is not exit 0
  exc::app::set_loop_float_mode();  // the plant steps as in the loop (docs/floating-point.md)
  CLI::App app{"Plant figures: step time per integrator x formulation (dig scene with force actuators, 1 kHz), the "
               "hydraulic step per pressure method and the dig scene's real-time factor through its valves, and the "
               "largest stable step per integrator in stiff clay.",
               "excavator-plant-bench"};
  std::string scene_path = std::string(EXC_SOURCE_DIR_BENCH) + "/scenes/dig.yaml";
  int repeats = 3;
  app.add_option("--scene", scene_path, "the dig scene (default: scenes/dig.yaml)");
  app.add_option("--repeats", repeats, "runs of the dig scene for the real-time factors (best is reported)")
      ->check(exc::cli::count_in(1, 1000));
  long profile_steps = 0;
  app.add_option("--profile-steps", profile_steps,
                 "only step the scene through its valves (its own pressure method) this many cycles, then print what "
                 "the steps did: the run to count under valgrind --tool=callgrind "
                 "--toggle-collect='exc::plant::Plant::step(*)' (docs/plant.md)")
      ->check(exc::cli::count_in(1, 100000000));
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;

  Scene base;
  control::Task task;
  try {
    const settings::Document scene = settings::Document::load(scene_path);  // read and parsed once
    base = read_scene(scene);
    task = control::read_task(scene, base.machine);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-plant-bench: %s\n", e.what());
    return 2;
  }

  if (profile_steps > 0) {
    // One run, nothing else: under callgrind, Plant::step's inclusive count over its calls is the
    // hydraulic step's cost in instructions.
    Scene s = base;
    s.actuators.fidelity = "hydraulic";
    const ValveDriver driver(task, s.machine);
    Plant p(s);
    ActuatorCommand c;
    c.mode = ActuatorCommand::valve;
    double iterations = 0, sweeps = 0, stuck = 0;
    for (long k = 0; k < profile_steps; ++k) {
      c.value = driver.opening(p.state().time, p.state());
      if (!p.step(c).ok()) {
        std::fprintf(stderr, "excavator-plant-bench: %s\n", p.status().text());
        return 1;
      }
      iterations += p.state().hydraulics.solver_iterations;
      sweeps += p.state().friction_sweeps;
      stuck += std::bitset<4>(p.state().friction_stuck).count();
    }
    const double n = static_cast<double>(profile_steps);
    std::printf("stepped %ld cycles of %s through its valves (%s pressures): per cycle %.2f chamber iterations, %.2f "
                "dry-friction sweeps, %.2f functions held by their static friction\n",
                profile_steps, s.name.c_str(), to_string(s.integrator.pressure_method), iterations / n, sweeps / n,
                stuck / n);
    return 0;
  }

  // The mechanics' cost: the scene with ideal force actuators, driven by the task's efforts.
  Scene forces = base;
  forces.actuators.fidelity = "ideal";
  std::printf("## Plant step time, dig scene with ideal force actuators at 1 kHz (step = cycle = 1 ms), per "
              "integrator x formulation\n\n");
  std::printf("| method | formulation | median us | p99 us | max us | real-time factor | finished |\n|---|---|---|---|---|---|---|\n");
  for (const IntegrationMethodEntry& method : integration_methods().entries()) {
    for (const auto& [f, formulation_name, formulation_what] : kFormulations.entries) {
      Scene s = forces;
      s.integrator.method = method.name;
      s.integrator.formulation = f;
      TaskDriver driver(task, s.machine);
      Plant p(s);
      std::vector<double> us;
      const long n = std::lround(s.duration / s.cycle);
      us.reserve(n);
      bool ok = true;
      ActuatorCommand c;
      for (long k = 0; k < n && ok; ++k) {
        c.value = driver.effort(p.state().time, p.state());
        const auto a = Clock::now();
        ok = p.step(c).ok();
        us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - a).count());
      }
      const Stats st = stats(us);
      double total = 0;
      for (double x : us) total += x;
      std::printf("| %s | %s | %.2f | %.2f | %.1f | %.0fx | %s |\n", method.name.c_str(), to_string(f), st.median, st.p99,
                  st.max, p.state().time / (total * 1e-6), ok ? "yes" : p.status().text());
    }
  }

  // The hydraulic step: the scene as shipped (hydraulic, its own integrator) driven through its
  // valves, with each way of integrating the pressures; the real-time factor is the best of
  // 'repeats' runs, the step statistics from all of them.
  if (!fidelity_of(base.actuators).has(kHydraulicCircuit))
    std::printf("\n(the scene is not hydraulic: the hydraulic rows run it with actuators.fidelity hydraulic)\n");
  std::printf("\n## Hydraulic step, dig scene through its valves (%s / %s, %g ms; chambers: 8 scalar solves per "
              "substep)\n\n| pressures | median us | p99 us | max us | chamber iterations per step: mean, p99 "
              "(per solve) | real-time factor | finished |\n|---|---|---|---|---|---|---|\n",
              base.integrator.method.c_str(), to_string(base.integrator.formulation), base.integrator.step * 1e3);
  for (const auto& [pm, pm_name, pm_what] : kPressureMethods.entries) {
    Scene s = base;
    s.actuators.fidelity = "hydraulic";
    s.integrator.pressure_method = pm;
    const ValveDriver driver(task, s.machine);
    std::vector<double> us, iterations;
    double best = 0, depth = 0;
    std::string failure = "yes";
    for (int r = 0; r < repeats; ++r) {
      Plant p(s);
      ActuatorCommand c;
      c.mode = ActuatorCommand::valve;
      const long n = std::lround(s.duration / s.cycle);
      double plant_s = 0;
      for (long k = 0; k < n; ++k) {
        c.value = driver.opening(p.state().time, p.state());
        const auto a = Clock::now();
        const bool ok = p.step(c).ok();
        const double dt = std::chrono::duration<double>(Clock::now() - a).count();
        if (!ok) {
          failure = p.status().text();
          break;
        }
        plant_s += dt;
        us.push_back(dt * 1e6);
        iterations.push_back(p.state().hydraulics.solver_iterations);
        depth = std::max(depth, p.state().depth);
      }
      best = std::max(best, p.state().time / plant_s);
    }
    const Stats st = stats(us), it = stats(iterations);
    double mean_it = 0;
    for (double x : iterations) mean_it += x / static_cast<double>(iterations.size());
    std::printf("| %s | %.2f | %.2f | %.1f | %.1f, %.0f (%.2f) | %.0fx over the run (1 s in %.2f ms), %.0fx at the median; "
                "deepest %.2f m | %s |\n", pm_name, st.median, st.p99, st.max, mean_it, it.p99, mean_it / 8, best, 1e3 / best,
                s.cycle * 1e6 / st.median, depth, failure.c_str());
  }

  // Real-time factor of the scene with ideal force actuators (the paper's), best of 'repeats'.
  double best = 0, reanchors = 0, depth = 0, best_median = 1e9;
  for (int r = 0; r < repeats; ++r) {
    TaskDriver driver(task, forces.machine);
    Plant p(forces);
    ActuatorCommand c;
    double plant_s = 0;
    const long n = std::lround(forces.duration / forces.cycle);
    std::vector<double> us;
    us.reserve(n);
    for (long k = 0; k < n; ++k) {
      c.value = driver.effort(p.state().time, p.state());
      const auto a = Clock::now();
      if (!p.step(c).ok()) break;
      const double dt = std::chrono::duration<double>(Clock::now() - a).count();
      plant_s += dt;
      us.push_back(dt * 1e6);
      depth = std::max(depth, p.state().depth);
    }
    best = std::max(best, p.state().time / plant_s);
    best_median = std::min(best_median, stats(us).median);
    reanchors = p.state().reanchor_count;
  }
  std::printf("\n## Dig scene with ideal force actuators (%s / %s, %g ms): real-time factor %.0fx over the whole run "
              "(1 s in %.2f ms), %.0fx at the median step of %.2f us (target >= 200x: 1 s in 5 ms); deepest %.2f m, %g "
              "re-anchorings\n",
              forces.integrator.method.c_str(), to_string(forces.integrator.formulation), forces.integrator.step * 1e3,
              best, 1e3 / best, forces.cycle * 1e6 / best_median, best_median, depth, reanchors);

  std::printf("\n## Largest stable step in stiff clay (tip 0.1 m in, moving into it, 2 s; bisection)\n\n");
  std::printf("| method | formulation | largest stable step ms | first failure |\n|---|---|---|---|\n");
  for (const IntegrationMethodEntry& method : integration_methods().entries()) {
    for (const auto& [f, formulation_name, formulation_what] : kFormulations.entries) {
      double lo = 0, hi = 0;
      std::string why, why_hi;
      for (double h = 1e-3; h <= 1.0; h *= 2) {
        if (stable_in_stiff_clay(base, method.name, f, h, why)) {
          lo = h;
        } else {
          hi = h;
          why_hi = why;
          break;
        }
      }
      if (hi > 0 && lo > 0) {
        for (int i = 0; i < 6; ++i) {
          const double mid = std::sqrt(lo * hi);
          if (stable_in_stiff_clay(base, method.name, f, mid, why)) lo = mid;
          else {
            hi = mid;
            why_hi = why;
          }
        }
      }
      const std::string short_why = why_hi.empty() ? "none up to 1 s" : why_hi.substr(why_hi.find(": ") + 2, 70);
      std::printf("| %s | %s | %.1f | %s |\n", method.name.c_str(), to_string(f), lo * 1e3, short_why.c_str());
    }
  }
  return 0;
}
