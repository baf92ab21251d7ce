#include "contact_report.hpp"

#include <cmath>
#include <iomanip>

namespace appell::cli {

ContactReport::ContactReport(const Scene& scene) {
  int offset = 0;
  for (size_t k = 0; k < scene.constraints.size(); ++k) {
    const Constraint& c = *scene.constraints[k];
    Entry e;
    e.name = c.name();
    // μ belongs to the contact; constraints the scene does not declare as contacts have none.
    const bool declared = k < scene.contacts.size() && scene.contacts[k] == scene.constraints[k];
    e.mu = declared ? scene.contacts[k]->mu() : std::numeric_limits<double>::infinity();
    for (int r = 0; r < c.rows(); ++r) {
      const std::string label = c.rowLabel(r);
      // λ of a row with direction t is the force along t on the body (constraint.hpp),
      // so the normal row carries the normal load and tangent/lateral rows friction.
      if (label == "normal") e.normal = offset + r;
      if (label == "tangent1" || label == "tangent2" || label == "lateral")
        e.tangential.push_back(offset + r);
    }
    offset += c.rows();
    entries_.push_back(e);
  }
}

void ContactReport::sample(double t, const VecX& lambda) {
  ++samples_;
  for (Entry& e : entries_) {
    if (e.normal < 0) continue;
    const double fn = lambda[e.normal];
    double ft2 = 0;
    for (int r : e.tangential) ft2 += lambda[r] * lambda[r];
    const double ft = std::sqrt(ft2);
    e.min_normal = std::min(e.min_normal, fn);
    e.max_normal = std::max(e.max_normal, fn);
    if (fn <= 0) {
      if (e.pulling++ == 0) e.first_pull = t;
      continue;
    }
    const double demand = ft / fn;
    if (demand > e.max_demand) {
      e.max_demand = demand;
      e.t_max_demand = t;
    }
    if (demand > e.mu && e.over_mu++ == 0) e.first_slip = t;
  }
}

int ContactReport::flagged() const {
  int n = 0;
  for (const Entry& e : entries_) n += (e.pulling > 0 || e.over_mu > 0);
  return n;
}

void ContactReport::print(std::ostream& out) const {
  if (entries_.empty()) return;
  out << "contacts (over " << samples_ << " samples):\n";
  for (const Entry& e : entries_) {
    out << "  " << std::left << std::setw(24) << e.name << std::right;
    if (e.normal < 0) {
      out << " (no normal row)\n";
      continue;
    }
    out << std::setprecision(4) << " normal load " << e.min_normal << " … " << e.max_normal << " N";
    if (!e.tangential.empty()) {
      out << ", friction demand max " << e.max_demand << " at t=" << e.t_max_demand;
      if (std::isfinite(e.mu)) out << " (μ = " << e.mu << ")";
    }
    if (e.over_mu) out << "  ⚠ exceeds μ in " << e.over_mu << " samples from t=" << e.first_slip << ": would slip";
    if (e.pulling) out << "  ⚠ normal pulls in " << e.pulling << " samples from t=" << e.first_pull << ": would lift off";
    out << "\n";
  }
}

}  // namespace appell::cli
