// A body moved as the scene prescribes (a drive, a shaker table, a spinning hub): its velocity and
// angular velocity are given functions of time, its pose their integrals. It is no state of any
// analysis: static, modal and buckling analyses hold it at its initial pose (the motion starts
// from rest of the integrals: every displacement and angle is 0 at t = 0), a transient moves it
// (docs/model.md "Prescribed motion").
#pragma once

#include "core/model/time_function.hpp"
#include "core/model/types.hpp"

namespace beamrail {

struct PrescribedMotion {
  // Velocity of the centre, global axes [m/s], times velocity_time(t); the centre is at
  // position + velocity * integral of velocity_time from 0 to t.
  Vec3 velocity = Vec3::Zero();
  TimeFunction velocity_time;
  // Angular velocity, global axes [rad/s], times angular_velocity_time(t): a rotation about the
  // body's centre about the fixed axis angular_velocity / |angular_velocity| through the angle
  // |angular_velocity| * integral of angular_velocity_time from 0 to t.
  Vec3 angular_velocity = Vec3::Zero();
  TimeFunction angular_velocity_time;
};

}  // namespace beamrail
