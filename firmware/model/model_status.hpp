#pragma once
// Typed outcomes of the model's algorithms. The real-time path returns these; it never throws and
// never returns NaN: a state with no assembly or near the four-bar toggle is reported instead.
namespace exc {

enum class ModelStatus {
  ok = 0,
  non_finite_input,   // a NaN or Inf was passed in
  no_assembly,        // a cylinder length outside its triangle inequality (loop cannot close)
  near_toggle,        // the bucket four-bar (or any loop) is near a singular position
  not_converged,      // the Newton loop-closure iteration did not converge
  singular,           // a linear system (M_a, KKT matrix) could not be solved
};

const char* to_string(ModelStatus s);

// What went wrong, where, and how badly conditioned: filled by loop closure and dynamics.
struct ModelReport {
  ModelStatus status = ModelStatus::ok;
  int loop = -1;             // 0..3: the loop (Table 2) concerned, -1 if none
  double conditioning = 0;   // reciprocal condition estimate of H_p (1 = perfect, 0 = singular)
  bool ok() const { return status == ModelStatus::ok; }
};

// Its one double to a state visitor (the shape of the firmware's control::StateVisitor; a template,
// so the model includes no floor above it), for a subnormal scan (docs/floating-point.md).
template <typename Visitor>
void visit_state(const ModelReport& r, Visitor& v) {
  v.visit("model report conditioning", r.conditioning);
}

}  // namespace exc
