// The MJCF export against independent evidence: the machine file's reference poses (pin and tip
// positions measured from the drawing, not computed by the exporter) and the project's own inverse
// dynamics (two formulations of the same mechanism: MuJoCo's tree + connect constraints vs the
// closed chain's Psi^T tau_r). Without MuJoCo the checks that need it report SKIPPED.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include "mjcf_export.hpp"
#include "model/closed_chain.hpp"
#include "model/loop_closure.hpp"
#include "model/machine_reader.hpp"
#include "scratch_files.hpp"
#ifdef EXC_HAVE_MUJOCO
#include "mujoco_peer.hpp"
#endif

namespace {

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

[[maybe_unused]] exc::Vec3 pin_of(const exc::ReferencePose& pose, const std::string& name) {
  for (const auto& [n, p] : pose.pins_world)
    if (n == name) return p;
  FAIL("reference pose has no pin " << name);
  return exc::Vec3::Zero();
}

}  // namespace

TEST_CASE("tools/export-mjcf writes 12 bodies, 12 joints, 4 connect loops and 4 motors") {
  const exc::Model model = exc::build_model(exc::load_machine(EXC_MACHINE_FILE));
  const std::string xml = exc::bench::export_mjcf(model, model.machine.reference_poses.front().q_a);
  CHECK(count(xml, "<body ") == 12);
  CHECK(count(xml, "<joint ") == 12);
  CHECK(count(xml, "type=\"slide\"") == 3);
  CHECK(count(xml, "<connect ") == 4);
  CHECK(count(xml, "<motor ") == 4);
  CHECK(count(xml, "gear=\"1\"") == 4);
  CHECK(xml.find("gravity=\"0 0 -9.81\"") != std::string::npos);
  // Every connect names the Table 2 pair.
  CHECK(xml.find("body1=\"boom\" body2=\"boom_rod\"") != std::string::npos);
  CHECK(xml.find("body1=\"arm\" body2=\"arm_rod\"") != std::string::npos);
  CHECK(xml.find("body1=\"arm\" body2=\"link12\"") != std::string::npos);
  CHECK(xml.find("body1=\"bucket\" body2=\"link11\"") != std::string::npos);
}

TEST_CASE("tools/excavator-bench export-mjcf writes the file it is given, and a write that fails (a full disk) is exit 1 naming it") {
  const std::string dir = exc::test::scratch_dir(std::string(EXC_BINARY_DIR) + "/tests/bench/mjcf_out_" +
                                                 std::to_string(getpid())).string();
  const std::string good = std::string(EXC_BENCH_EXE) + " export-mjcf -o " + dir + "/m.xml 2> " + dir + "/good.err";
  CHECK(std::system(good.c_str()) == 0);
  std::ifstream in(dir + "/m.xml");
  const std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(count(xml, "<connect ") == 4);
  REQUIRE(std::filesystem::exists("/dev/full"));
  const std::string full = std::string(EXC_BENCH_EXE) + " export-mjcf -o /dev/full 2> " + dir + "/full.err";
  const int raw = std::system(full.c_str());
  CHECK(WIFEXITED(raw));
  CHECK(WEXITSTATUS(raw) == 1);
  std::ifstream err(dir + "/full.err");
  const std::string message((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  CHECK(message.find("/dev/full: cannot write") != std::string::npos);
}

TEST_CASE("tools/export-mjcf refuses a pose where the loops cannot close") {
  const exc::Model model = exc::build_model(exc::reference_machine());
  const exc::Vec4 impossible(0.0, 9.0, 2.3, 2.1);  // a 9 m boom cylinder
  CHECK_THROWS_WITH_AS(exc::bench::export_mjcf(model, impossible), doctest::Contains("do not close"),
                       std::runtime_error);
}

TEST_CASE("tools/export-mjcf in MuJoCo reproduces the machine file's reference poses") {
#ifndef EXC_HAVE_MUJOCO
  std::printf("SKIPPED: MuJoCo (libmujoco-dev) not installed\n");
#else
  const exc::Model model = exc::build_model(exc::load_machine(EXC_MACHINE_FILE));
  const auto& poses = model.machine.reference_poses;
  REQUIRE(poses.size() >= 2);
  const std::string path = std::string(EXC_BINARY_DIR) + "/tests/bench/reference.mjcf.xml";
  std::ofstream(path) << exc::bench::export_mjcf(model, poses.front().q_a);
  std::string error;
  auto peer = exc::bench::MujocoPeer::load(model, path, error);
  REQUIRE_MESSAGE(peer, error);
  double mass = 0;
  for (const auto& b : model.machine.bodies) mass += b.mass;
  CHECK(peer->total_mass() == doctest::Approx(mass).epsilon(1e-12));
  // MuJoCo placed the second anchors from the exported configuration: they must be our pin points.
  for (int l = 0; l < exc::kNumLoops; ++l)
    CHECK((peer->compiled_anchor2(l) - model.loops[l].point_s).norm() < 1e-9);
  exc::Workspace ws(model);
  for (const auto& pose : poses) {
    REQUIRE(exc::solve_loop_closure(model, ws, pose.q_a).ok());
    peer->set_state(ws.q, exc::Vec12::Zero());
    CHECK(peer->constraint_error() < 1e-9);
    CHECK((peer->tip_world() - pin_of(pose, "T")).norm() < 5e-4);  // the file's 0.5 mm
  }
#endif
}

TEST_CASE("tools/export-mjcf: MuJoCo's inverse dynamics equals the closed chain's tau_a") {
#ifndef EXC_HAVE_MUJOCO
  std::printf("SKIPPED: MuJoCo (libmujoco-dev) not installed\n");
#else
  const exc::Model model = exc::build_model(exc::load_machine(EXC_MACHINE_FILE));
  const std::string path = std::string(EXC_BINARY_DIR) + "/tests/bench/dynamics.mjcf.xml";
  std::ofstream(path) << exc::bench::export_mjcf(model, model.machine.reference_poses.front().q_a);
  std::string error;
  auto peer = exc::bench::MujocoPeer::load(model, path, error);
  REQUIRE_MESSAGE(peer, error);
  exc::Workspace ws(model);
  // Moving states with accelerations; Psi^T removes any loop force (H Psi = 0), so Psi^T of MuJoCo's
  // generalised forces must be our tau_a whatever MuJoCo's soft constraints contribute.
  const exc::Vec4 q_a[] = {exc::Vec4(0.0, 2.4626, 2.3231, 2.1447), exc::Vec4(0.5, 1.9, 3.0, 1.8),
                           exc::Vec4(-0.3, 2.2, 2.6, 2.0)};
  const exc::Vec4 qd_a(0.3, 0.1, -0.15, 0.2), qdd_a(0.5, -0.2, 0.3, 0.4);
  for (const exc::Vec4& q : q_a) {
    REQUIRE(exc::update_closed_chain(model, ws, q, qd_a).ok());
    exc::Vec4 tau_a;
    exc::inverse_dynamics(model, ws, qdd_a, exc::Vec2::Zero(), tau_a);
    const exc::Vec12 qdd = ws.Psi * qdd_a + ws.gamma;
    exc::Vec12 tau_mj;
    peer->inverse(ws.q, ws.qd, qdd, tau_mj);
    const exc::Vec4 tau_a_mj = ws.Psi.transpose() * tau_mj;
    INFO("q_a = " << q.transpose() << "\nours   " << tau_a.transpose() << "\nMuJoCo " << tau_a_mj.transpose());
    for (int i = 0; i < 4; ++i) CHECK(tau_a_mj[i] == doctest::Approx(tau_a[i]).epsilon(1e-6).scale(1.0));
  }
#endif
}
