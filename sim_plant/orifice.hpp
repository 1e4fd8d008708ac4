#pragma once
// Orifice flow (hydraulics.md): Q = K_v x sqrt(dp), laminar below ~0.2 MPa.

namespace exc::plant {

// Flow for unit gain and opening, and its derivative with respect to dp. Linear below the laminar
// pressure (meeting the square root there) so that the flow and its derivative stay finite at dp = 0.
void orifice_flow(double dp, double laminar_pressure, double& flow, double& dflow_ddp);

}  // namespace exc::plant
