// The point-jump stage: after a step, a closed contact whose contact point
// jumped (a disk falling flat) may approach its support faster than
// rest_speed: an impact at the step's end, resolved by the mode decisions.
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

namespace appell {

/// A closed contact whose contact point jumped inside the step — a disk
/// falling flat, whose lowest rim point runs round the rim — approaches the
/// support at the step's end faster than rest_speed. That is an impact:
/// resolved here, at the step's end, by the same impact and force problems as
/// a touchdown, its energy loss counted — instead of being absorbed unseen by
/// the drift projection. (A terrain's change of piece is located instead:
/// contact_features.cpp.) `rows_current` on entry: cdata_ and data_ hold the
/// rows at (t_, q_, v_); on return: they still do (no impact).
bool Simulator::Impl::pointJumpImpact(std::string& error, bool& rows_current) {
  auto& u = *uni_;
  // The rows at the step's end; their forward kinematics (q, v) leave the
  // bodies' velocities in data_ for the normal velocities below.
  if (!rows_current) evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  rows_current = false;
  bool approaching = false;
  for (const auto& r : u.rows) {
    if (r.joint || !cdata_->isActive(r.c)) continue;
    const RowBlock& blk = cdata_->blocks[r.c];
    double gamma = blk.b[r.row];
    if (r.a >= 0) gamma += blk.Wa.row(r.row).dot(data_->oMi[r.a].act(data_->v[r.a]));
    if (r.b >= 0) gamma -= blk.Wb.row(r.row).dot(data_->oMi[r.b].act(data_->v[r.b]));
    approaching = approaching || gamma < -options_.contacts.rest_speed;
  }
  if (!approaching) {
    rows_current = true;
    return true;
  }
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_, true);
    if (!projection_.ok) {
      error = "position projection failed: " + projection_.error;
      return false;
    }
  }
  forwardKinematics(model_, *data_, q_, v_);
  const double T_before = appell::kineticEnergy(model_, *data_, q_, v_);
  for (auto& r : u.rows) r.lifting = r.touching_down = false;
  if (!decideModes(error) || !frictionPhase(error) || !projectAfterModes(error)) return false;
  dissipated_ += T_before - appell::kineticEnergy(model_, *data_, q_, v_);
  integrator_->reset();
  return true;
}

}  // namespace appell
