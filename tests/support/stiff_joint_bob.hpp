// A 1 kg bob (own inertia 1e-3 kg m^2) hanging at rest 0.3 m below a revolute joint about z of
// relative compliance 1e-9 (stiff modes of about 2.4e6 rad/s), under gravity (-y) and a 1e-3 N m
// torque sin(4 pi t) about z. Its closed form (small swings: sin theta = theta to 1e-8 of the
// motion): I theta'' + m g L theta = T sin(W t), I = m L^2 + I_c, from rest, so theta = T / (I
// (w^2 - W^2)) (sin W t - (W / w) sin w t), w^2 = m g L / I; the bob's centre is at x = L sin
// theta from the joint (a swing of about 78 um over 1 s).
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace beamrail::testing {

// The bob's parameters, shared by the scene and its closed form.
inline constexpr double kBobMass = 1.0, kBobArm = 0.3, kBobOwnInertia = 1e-3, kBobTorque = 1e-3;
inline constexpr double kBobGravity = 9.81, kBobLoadHz = 2.0;

// The scene JSON text, the joint at `pivot` [m].
inline std::string stiff_joint_bob(const std::array<double, 3>& pivot = {0.0, 0.0, 0.0}) {
  const auto n = [](double v) { return std::to_string(v); };
  const auto at = [&n](double x, double y, double z) {
    return "[" + n(x) + ", " + n(y) + ", " + n(z) + "]";
  };
  return R"({"gravity": [0, )" + n(-kBobGravity) + R"(, 0],
    "bodies": [{"name": "bob", "mass": )" +
         n(kBobMass) + R"(, "inertia": )" + at(kBobOwnInertia, kBobOwnInertia, kBobOwnInertia) +
         R"(, "position": )" + at(pivot[0], pivot[1] - kBobArm, pivot[2]) + R"(}],
    "joints": [{"name": "pivot", "type": "revolute", "body1": "ground", "body2": "bob",
                "point": )" +
         at(pivot[0], pivot[1], pivot[2]) + R"(, "axis": [0, 0, 1], "relative_compliance": 1e-9}],
    "loads": [{"type": "torque", "body": "bob", "value": )" +
         at(0.0, 0.0, kBobTorque) + R"(, "time": {"type": "harmonic", "frequency": )" +
         n(kBobLoadHz) + R"(}}]})";
}

// The closed form's x of the bob's centre at t, from the joint [m].
inline double stiff_joint_bob_x(double t) {
  const double inertia = kBobMass * kBobArm * kBobArm + kBobOwnInertia;
  const double w = std::sqrt(kBobMass * kBobGravity * kBobArm / inertia);
  const double W = 2.0 * std::numbers::pi * kBobLoadHz;
  const double theta =
      kBobTorque / (inertia * (w * w - W * W)) * (std::sin(W * t) - W / w * std::sin(w * t));
  return kBobArm * std::sin(theta);
}

}  // namespace beamrail::testing
