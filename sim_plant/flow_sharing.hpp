#pragma once
// How the pumps share their flow among the functions they feed. The rule modelled is load sensing
// with post-compensators (flow sharing, as the PC200-8's closed-centre CLSS, hydraulics.md):
//   - the pump holds its pressure a fixed margin above the highest load among the open functions,
//     at most the main relief (the pump's pressure cut-off);
//   - every open meter-in orifice sees that same margin as its drop, so each function's flow is
//     its opening's flow at the margin, whatever its load;
//   - when those flows together exceed what the pump delivers, the common drop falls and every
//     function's flow scales by the same factor, pump flow / demand: all of them slow, in the ratio
//     of their demands, and the total equals the pump's flow.
// Negative-flow control (Hitachi, Kawasaki) shares differently (the lighter load takes more); it is
// not modelled.

namespace exc::plant {

// The pump's pressure: highest load of the open functions plus the margin, capped at the main
// relief. With nothing open the pump stands by at tank + margin.
double load_sensing_pressure(bool any_open, double highest_load, double tank, double margin, double main_relief);

// The factor every function's meter-in flow is multiplied by: 1 while the pump covers the demand,
// pump_flow / demand beyond it.
double flow_share_scale(double demand, double pump_flow);

}  // namespace exc::plant
