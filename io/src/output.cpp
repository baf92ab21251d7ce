#include <appell/output.hpp>

#include <charconv>
#include <stdexcept>

namespace appell {

namespace {

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

}  // namespace

std::vector<std::string> trajectoryColumns(const Model& model, const ConstraintList& constraints) {
  std::vector<std::string> cols = {"time"};
  for (const char* prefix : {"q:", "v:"})
    for (const std::string& c : coordinateNames(model, prefix[0] == 'v')) cols.push_back(prefix + c);
  cols.push_back("energy");
  cols.push_back("residual");
  for (const auto& con : constraints) {
    for (const char* xyz : {".x", ".y", ".z"}) cols.push_back("point:" + con->name() + xyz);
    for (const char* xyz : {".x", ".y", ".z"}) cols.push_back("normal:" + con->name() + xyz);
    for (int k = 0; k < con->rows(); ++k)
      cols.push_back("lambda:" + con->name() + "." + con->rowLabel(k));
    if (con->unilateral()) {
      cols.push_back("closed:" + con->name());
      cols.push_back("event:" + con->name());
    }
  }
  return cols;
}

TrajectoryWriter::TrajectoryWriter(std::ostream& out, const Scene& scene)
    : TrajectoryWriter(out, scene.model, scene.constraints) {}

TrajectoryWriter::TrajectoryWriter(std::ostream& out, const Model& model,
                                   const ConstraintList& constraints)
    : out_(out),
      nq_(model.nq),
      nv_(model.nv),
      nconstraints_(static_cast<int>(constraints.size())),
      nrows_(0),
      columns_(trajectoryColumns(model, constraints)) {
  for (const auto& c : constraints) {
    rows_.push_back(c->rows());
    unilateral_.push_back(c->unilateral() ? 1 : 0);
    nrows_ += c->rows();
  }
  std::string header;
  for (std::size_t k = 0; k < columns_.size(); ++k)
    header += (k ? "," : "") + csvField(columns_[k]);
  out_ << header << '\n';
  line_.reserve(columns_.size() * 24);
}

void TrajectoryWriter::put(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  if (!line_.empty()) line_ += ',';
  line_.append(buf, r.ptr);
}

void TrajectoryWriter::write(double t, const VecX& q, const VecX& v, double energy,
                             double residual, const std::vector<ContactFrame>& frames,
                             const VecX& lambda, const std::vector<ContactState>& states) {
  if (!states.empty() && static_cast<int>(states.size()) != nconstraints_)
    throw std::invalid_argument("TrajectoryWriter::write: " + std::to_string(states.size()) +
                                " contact states for " + std::to_string(nconstraints_) +
                                " constraints");
  if (q.size() != nq_ || v.size() != nv_ || static_cast<int>(frames.size()) != nconstraints_ ||
      lambda.size() != nrows_)
    throw std::invalid_argument(
        "TrajectoryWriter::write: sizes q " + std::to_string(q.size()) + "/" + std::to_string(nq_) +
        ", v " + std::to_string(v.size()) + "/" + std::to_string(nv_) + ", frames " +
        std::to_string(frames.size()) + "/" + std::to_string(nconstraints_) + ", lambda " +
        std::to_string(lambda.size()) + "/" + std::to_string(nrows_) + " (given/expected)");
  line_.clear();
  put(t);
  for (int i = 0; i < nq_; ++i) put(q(i));
  for (int i = 0; i < nv_; ++i) put(v(i));
  put(energy);
  put(residual);
  int row = 0;
  for (int c = 0; c < nconstraints_; ++c) {
    for (int k = 0; k < 3; ++k) put(frames[c].point(k));
    for (int k = 0; k < 3; ++k) put(frames[c].normal(k));
    for (int k = 0; k < rows_[c]; ++k) put(lambda(row++));
    if (unilateral_[c]) {
      put(states.empty() || states[c].closed ? 1.0 : 0.0);
      put(states.empty() ? 0.0 : static_cast<double>(states[c].event));
    }
  }
  line_ += '\n';
  out_ << line_;
  ++samples_;
}

}  // namespace appell
