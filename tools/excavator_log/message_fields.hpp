#pragma once
// Field-by-field access to every exlcm type, in the order of its .lcm definition, so the exporter
// can write any channel as CSV. lcm-gen's C++ output has no reflection; this table is the one place
// that lists the fields, and tests/telemetry checks it against the .lcm files themselves.
//
// A visitor provides:
//   void number(const char* name, const T* values, int count)  (T: int64_t, int32_t, int8_t, double;
//        count > 1 for a fixed-size array, exported as name_0 ... name_{count-1})
//   void boolean(const char* name, const int8_t* values, int count)  (exported as 0 / 1)
//   void text(const char* name, const int8_t* chars, int capacity)  (NUL-terminated char array)
#include "exlcm/can_stats_t.hpp"
#include "exlcm/command_t.hpp"
#include "exlcm/controller_state_t.hpp"
#include "exlcm/fault_t.hpp"
#include "exlcm/machine_state_t.hpp"
#include "exlcm/telemetry_stats_t.hpp"
#include "exlcm/timing_t.hpp"

namespace exc::log {

template <class Visitor>
void visit_fields(const exlcm::machine_state_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("q_active", m.q_active, 4);
  v.number("qd_active", m.qd_active, 4);
  v.number("q_passive", m.q_passive, 8);
  v.number("tip_world", m.tip_world, 3);
  v.number("tip_rho", m.tip_rho, 2);
  v.number("soil_force", m.soil_force, 2);
  v.number("soil_anchor", m.soil_anchor, 2);
  v.boolean("in_soil", &m.in_soil, 1);
  v.number("depth", &m.depth, 1);
}

template <class Visitor>
void visit_fields(const exlcm::command_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("mode", &m.mode, 1);
  v.number("controller", &m.controller, 1);
  v.number("effort", m.effort, 4);
  v.number("valve", m.valve, 4);
  v.boolean("saturated", m.saturated, 4);
}

template <class Visitor>
void visit_fields(const exlcm::controller_state_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("controller", &m.controller, 1);
  v.number("mode", &m.mode, 1);
  v.number("q_desired", m.q_desired, 4);
  v.number("qd_desired", m.qd_desired, 4);
  v.number("error", m.error, 4);
  v.number("error_rate", m.error_rate, 4);
  v.number("theta_hat", m.theta_hat, 6);
  v.number("theta_true", m.theta_true, 6);
  v.number("lyapunov", &m.lyapunov, 1);
}

template <class Visitor>
void visit_fields(const exlcm::timing_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("stage", &m.stage, 1);
  v.number("count", &m.count, 1);
  v.number("min_us", &m.min_us, 1);
  v.number("median_us", &m.median_us, 1);
  v.number("p99_us", &m.p99_us, 1);
  v.number("max_us", &m.max_us, 1);
  v.number("overruns", &m.overruns, 1);
  v.number("skipped", &m.skipped, 1);
  v.number("bin_width_us", &m.bin_width_us, 1);
  v.number("bins", m.bins, 64);
}

template <class Visitor>
void visit_fields(const exlcm::can_stats_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("node", &m.node, 1);
  v.number("tx", &m.tx, 1);
  v.number("rx_ok", &m.rx_ok, 1);
  v.number("stale", &m.stale, 1);
  v.number("repeated", &m.repeated, 1);
  v.number("corrupt", &m.corrupt, 1);
  v.number("wrong_dlc", &m.wrong_dlc, 1);
  v.number("unknown", &m.unknown, 1);
  v.number("dropped", &m.dropped, 1);
  v.number("bus_load", &m.bus_load, 1);
}

template <class Visitor>
void visit_fields(const exlcm::fault_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("code", &m.code, 1);
  v.number("severity", &m.severity, 1);
  v.boolean("active", &m.active, 1);
  v.text("text", m.text, sizeof m.text);
}

template <class Visitor>
void visit_fields(const exlcm::telemetry_stats_t& m, Visitor& v) {
  v.number("utime", &m.utime, 1);
  v.number("seq", &m.seq, 1);
  v.number("enqueued", &m.enqueued, 1);
  v.number("published", &m.published, 1);
  v.number("dropped_overflow", &m.dropped_overflow, 1);
  v.number("dropped_too_large", &m.dropped_too_large, 1);
  v.number("publish_errors", &m.publish_errors, 1);
  v.number("dropped_full", m.dropped_full, 7);
  v.number("blocked", &m.blocked, 1);
  v.number("ring_high_water", &m.ring_high_water, 1);
  v.number("ring_capacity", &m.ring_capacity, 1);
  v.number("overflow_policy", &m.overflow_policy, 1);
}

// Calls f(prototype) with a value-initialised message of the exlcm type whose LCM fingerprint is
// `hash`; returns false if no exlcm type has that fingerprint.
template <class F>
bool with_type_of_fingerprint(std::int64_t hash, F&& f) {
  if (hash == exlcm::machine_state_t::getHash()) return f(exlcm::machine_state_t{}), true;
  if (hash == exlcm::command_t::getHash()) return f(exlcm::command_t{}), true;
  if (hash == exlcm::controller_state_t::getHash()) return f(exlcm::controller_state_t{}), true;
  if (hash == exlcm::timing_t::getHash()) return f(exlcm::timing_t{}), true;
  if (hash == exlcm::can_stats_t::getHash()) return f(exlcm::can_stats_t{}), true;
  if (hash == exlcm::fault_t::getHash()) return f(exlcm::fault_t{}), true;
  if (hash == exlcm::telemetry_stats_t::getHash()) return f(exlcm::telemetry_stats_t{}), true;
  return false;
}

}  // namespace exc::log
