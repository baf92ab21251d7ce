#include <appell/actuators.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace appell {

void Schedule::validate() const {
  if (t.empty()) throw std::invalid_argument("the set-point schedule has no points");
  if (t.size() != value.size()) throw std::invalid_argument("the set-point schedule's times and values differ in number");
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (!std::isfinite(t[k]) || !std::isfinite(value[k]))
      throw std::invalid_argument("set-point " + std::to_string(k + 1) + " is not finite");
    if (k > 0 && !(t[k] > t[k - 1]))
      throw std::invalid_argument("set-point " + std::to_string(k + 1) + " at t = " + std::to_string(t[k]) +
                                  " does not come after the one before (t = " + std::to_string(t[k - 1]) +
                                  "); times must increase");
  }
}

namespace {

// Index k of the segment [t_k, t_{k+1}) holding `time`, −1 before the first
// point, n − 1 at or after the last. Schedules are a handful of points: a
// binary search is O(log n) and allocation-free.
int segment(const Schedule& s, double time) {
  const auto it = std::upper_bound(s.t.begin(), s.t.end(), time);
  return static_cast<int>(it - s.t.begin()) - 1;
}


}  // namespace

double Schedule::at(double time) const {
  const int k = segment(*this, time);
  const int n = static_cast<int>(t.size());
  if (k < 0) return value.front();
  if (k >= n - 1) return value.back();
  const double s = (time - t[k]) / (t[k + 1] - t[k]);
  return value[k] + s * (value[k + 1] - value[k]);
}

double Schedule::rate(double time) const {
  const int k = segment(*this, time);
  if (k < 0 || k >= static_cast<int>(t.size()) - 1) return 0;
  return (value[k + 1] - value[k]) / (t[k + 1] - t[k]);
}

const char* toString(ActuatorType type) {
  return type == ActuatorType::Position ? "position" : "velocity";
}

void Actuator::validate(const Model& model) const {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("actuator '" + name + "': " + why);
  };
  if (joint < 0 || joint >= model.nbodies) fail("no joint " + std::to_string(joint));
  const JointType jt = model.joints[joint].type;
  if (!oneDofJoint(jt))
    fail(std::string("joint '") + model.joint_names[joint] + "' is " + toString(jt) +
         "; servos drive revolute, continuous and prismatic joints");
  if (!std::isfinite(kp) || kp < 0) fail("kp must be finite and ≥ 0");
  if (!std::isfinite(kv) || kv < 0) fail("kv must be finite and ≥ 0");
  if (type == ActuatorType::Velocity && kp != 0) fail("a velocity servo has no kp (its gain is kv)");
  if (type == ActuatorType::Velocity && kv == 0) fail("a velocity servo needs kv > 0");
  if (type == ActuatorType::Position && kp == 0) fail("a position servo needs kp > 0");
  if (!(effort_limit > 0)) fail("the effort limit must be > 0");
  try {
    setpoint.validate();
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
}

double Actuator::demand(double t, double q, double qdot) const {
  if (type == ActuatorType::Velocity) return kv * (setpoint.at(t) - qdot);
  return kp * (setpoint.at(t) - q) + kv * (setpoint.rate(t) - qdot);
}

double Actuator::force(double t, double q, double qdot) const {
  return std::clamp(demand(t, q, qdot), -effort_limit, effort_limit);
}

void applyActuators(const Model& model, const std::vector<Actuator>& actuators, double t,
                    const VecX& q, const VecX& v, VecX& tau) {
  for (const Actuator& a : actuators) {
    const Joint& j = model.joints[a.joint];
    tau[j.idx_v] += a.force(t, q[j.idx_q], v[j.idx_v]);
  }
}

}  // namespace appell
