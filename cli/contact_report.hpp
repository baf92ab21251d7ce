// Reading contact reactions the way a vehicle engineer does: normal load,
// friction demand |f_t| / f_n against the scene's μ, and pulling normals
// (the contact would lift off if it could).
#pragma once

#include <appell/scene.hpp>

#include <ostream>
#include <vector>

namespace appell::cli {

class ContactReport {
 public:
  explicit ContactReport(const Scene& scene);
  /// Accumulates one sample of the multipliers (one per constraint row).
  void sample(double t, const VecX& lambda);
  void print(std::ostream& out) const;
  /// Number of contacts whose friction demand exceeded μ, or that pulled.
  int flagged() const;

 private:
  struct Entry {
    std::string name;
    double mu;
    int normal = -1;              ///< row index of the normal, −1 if none
    std::vector<int> tangential;  ///< rows whose force lies in the tangent plane
    double max_demand = 0, t_max_demand = 0;
    double min_normal = std::numeric_limits<double>::infinity(), max_normal = 0;
    long pulling = 0, over_mu = 0;
    double first_pull = -1, first_slip = -1;
  };
  std::vector<Entry> entries_;
  long samples_ = 0;
};

}  // namespace appell::cli
