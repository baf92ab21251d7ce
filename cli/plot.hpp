// Plots of a run (appell plot, appell run --plot): gnuplot reads data files
// that this writes from the trajectory CSV, one PNG each —
//   energy.png     E(t) and the drift E(t) − E(0)
//   residuals.png  max(|A v + b|∞, max |gap|) per sample (log scale)
//   contacts.png   per contact: normal load λ_n, and the friction demand
//                  |f_t| / λ_n = sqrt(Σ λ_t²) / λ_n over the tangent and lateral
//                  rows against μ (the least μ that keeps the contact rolling
//                  by Coulomb's law; drawn when a scene gives μ)
//   path.png       the paths seen from above: planar/floating joint origins
//                  (q:<joint>.x, .y) and the contact points (point:<c>.x, .y)
//   joints.png     q and v of every one-degree-of-freedom joint, and its
//                  applied force τ (constant efforts + servos, evaluated at
//                  each sample) when the scene is given and drives joints
// Curves get distinct colours however many there are (seriesColour).
// The .dat and .gp files stay beside the PNGs, so a plot can be redrawn or
// restyled with `gnuplot NAME.gp` in that folder.
#pragma once

#include <appell/scene.hpp>

#include <string>
#include <vector>

namespace appell::cli {

/// Writes the data, scripts and PNGs into `dir` (created if needed) and returns
/// the PNG paths. `scene` (may be null) supplies μ per contact, by name, and
/// the joint forces τ.
/// Throws std::runtime_error when the CSV cannot be read or gnuplot fails.
std::vector<std::string> writePlots(const std::string& csv, const std::string& dir,
                                    const Scene* scene);

/// The stability diagram of `appell linearize --sweep … --plot FILE.png`: the
/// largest real part of the eigenvalues against the swept parameter, with the
/// zero line (FILE.dat and FILE.gp beside the PNG).
void writeStabilityPlot(const std::string& png, const std::string& parameter,
                        const std::vector<double>& values, const std::vector<double>& max_real);

/// The folder `appell plot` and `appell run --plot` use by default: next to
/// the CSV, named after it ("out/run.csv" → "out/run_plots").
std::string defaultPlotDir(const std::string& csv);

}  // namespace appell::cli
