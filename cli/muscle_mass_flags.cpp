#include "cli/muscle_mass_flags.hpp"

#include <cmath>
#include <iostream>
#include <memory>
#include <regex>
#include <stdexcept>

#include "core/muscles/wrap/network_model.hpp"

namespace redmax::cli {

const std::set<std::string>& muscleMassFlagNames() {
  static const std::set<std::string> names = {
      "muscle-mass",      "muscles",        "mass-points",   "mass-region",
      "specific-tension", "muscle-density", "transfer-body", "transfer-fraction",
      "wrap",             "wrap-width",     "wrap-network"};
  return names;
}

std::set<std::string> withMuscleMassFlags(std::set<std::string> names) {
  names.insert(muscleMassFlagNames().begin(), muscleMassFlagNames().end());
  return names;
}

bool hasWrapFlags(const Args& a) { return a.has("wrap") || a.has("wrap-width") || a.has("wrap-network"); }

void parseWrapFlags(const Args& a, osim::MuscleMassOptions& o) {
  // smooth by default: the mass matrix stays continuous at contact changes, so energy is conserved
  // to integrator error; exact (finite-difference J) jumps there [D Sec. 5.3.3, 6.2.4]
  const std::string model = a.get("wrap", "smooth");
  o.wrap = WrapMassOptions{};
  o.wrap_mass = model != "lumped";
  if (model == "smooth") {
    o.wrap.model = WrapModel::Smooth;
  } else if (model == "exact") {
    o.wrap.model = WrapModel::Exact;
  } else if (model == "neural") {
    o.wrap.model = WrapModel::Neural;
    if (!a.has("wrap-network") || a.get("wrap-network", "").empty())
      throw UsageError{"--wrap neural needs --wrap-network FILE (a network of `redmax train-wrap`, e.g. "
                       "osim_models/networks/cylinder_3x64.txt)"};
    const std::string file = a.get("wrap-network", "");
    try {
      o.wrap.network = loadWrapNetwork(file);
    } catch (const std::exception& e) {
      throw UsageError{std::string("--wrap-network: ") + e.what()};
    }
    // outside the training box the smooth model takes over: warn once per muscle, count them all
    o.wrap.monitor = std::make_shared<WrapFallbackMonitor>(
        [](const std::string& message) { std::cerr << "warning: " << message << "\n"; });
  } else if (model != "lumped") {
    throw UsageError{"--wrap must be smooth, exact, neural or lumped, got '" + model + "'"};
  }
  if (a.has("wrap-width")) {
    if (model != "smooth" && model != "neural")
      throw UsageError{"--wrap-width needs --wrap smooth or neural (the smooth model's transition width; neural "
                       "falls back to it)"};
    o.wrap.width = a.getDouble("wrap-width", 0.0);
    if (!(o.wrap.width > 0.0) || !std::isfinite(o.wrap.width))
      throw UsageError{"--wrap-width must be a positive number of metres, got '" + a.get("wrap-width", "") + "'"};
  }
  if (a.has("wrap-network") && model != "neural") throw UsageError{"--wrap-network needs --wrap neural"};
}

osim::MuscleMassOptions parseMuscleMassFlags(const Args& a) {
  using Source = osim::MuscleMassOptions::Source;
  osim::MuscleMassOptions o;
  const std::string source = a.get("muscle-mass", "none");
  try {
    o.source = osim::parseMuscleMassSource(source);
  } catch (const std::invalid_argument& e) {
    throw UsageError{e.what()};
  }
  if (o.source == Source::None) {
    for (const std::string& f : muscleMassFlagNames())
      if (f != "muscle-mass" && a.has(f))
        throw UsageError{"--" + f + " needs --muscle-mass physiological or transfer"};
    return o;
  }
  parseWrapFlags(a, o);
  if (o.source != Source::Transfer)
    for (const char* f : {"transfer-body", "transfer-fraction"})
      if (a.has(f)) throw UsageError{std::string("--") + f + " needs --muscle-mass transfer"};

  o.muscles = a.get("muscles", "all");
  if (o.muscles.empty()) throw UsageError{"--muscles needs all, top:K or a regular expression"};
  if (o.muscles.rfind("top:", 0) == 0) {
    const std::string k = o.muscles.substr(4);
    const bool digits = !k.empty() && k.size() <= 7 && k.find_first_not_of("0123456789") == std::string::npos;
    if (!digits || std::stol(k) < 1)
      throw UsageError{"--muscles top:K needs a whole number K >= 1, got '" + o.muscles + "'"};
  } else if (o.muscles != "all") {
    try {
      std::regex re(o.muscles, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw UsageError{"--muscles '" + o.muscles + "' is not a valid regular expression (" + e.what() + ")"};
    }
  }
  const long n = a.getInt("mass-points", o.mass_points);
  if (n < 1 || n > 100000) throw UsageError{"--mass-points must be between 1 and 100000, got " + std::to_string(n)};
  o.mass_points = static_cast<int>(n);
  const std::string region = a.get("mass-region", "fibre");
  if (region == "fibre" || region == "fiber") {
    o.region = MassPointOptions::Region::Fibre;
  } else if (region == "whole") {
    o.region = MassPointOptions::Region::WholePath;
  } else {
    throw UsageError{"--mass-region must be fibre or whole, got '" + region + "'"};
  }
  o.specific_tension = a.getDouble("specific-tension", o.specific_tension);
  if (!(o.specific_tension > 0.0)) throw UsageError{"--specific-tension must be > 0 (Pa)"};
  o.density = a.getDouble("muscle-density", o.density);
  if (!(o.density > 0.0)) throw UsageError{"--muscle-density must be > 0 (kg/m^3)"};

  if (o.source == Source::Transfer) {
    if (!a.has("transfer-body") || a.get("transfer-body", "").empty())
      throw UsageError{"--muscle-mass transfer needs --transfer-body BODY"};
    o.transfer_body = a.get("transfer-body", "");
    if (!a.has("transfer-fraction")) throw UsageError{"--muscle-mass transfer needs --transfer-fraction F"};
    o.transfer_fraction = a.getDouble("transfer-fraction", 0.0);
    if (!(o.transfer_fraction >= 0.0 && o.transfer_fraction < 1.0))
      throw UsageError{"--transfer-fraction must be in [0, 1), got " + a.get("transfer-fraction", "")};
  }
  return o;
}

const char* muscleMassUsage() {
  return "Muscle mass (default none: the model as OpenSim sees it, muscles lumped into the bones):\n"
         "  --muscle-mass none|physiological|transfer\n"
         "                       physiological: each muscle gets density * (max_isometric_force /\n"
         "                       specific tension) * optimal_fiber_length, taken from the bodies it was\n"
         "                       lumped into (total mass and centre of mass unchanged); transfer: a\n"
         "                       fraction of one body's mass moves into the muscles with a path point on it\n"
         "  --muscles all|REGEX|top:K  which muscles get mass (REGEX matches whole names; top:K the K\n"
         "                       largest ||M_muscle|| / ||M_skeleton|| over the trial); default all\n"
         "  --mass-points N      points per muscle (default 20)\n"
         "  --mass-region fibre|whole  points in the fibre part of the path (default) or along all of it\n"
         "  --specific-tension PA  default 600000 (60 N/cm^2, Rajagopal et al. 2016)\n"
         "  --muscle-density KG_M3 default 1059.7 (Ward & Lieber 2005)\n"
         "  --transfer-body BODY --transfer-fraction F   transfer only: F in [0, 1)\n"
         "  --wrap smooth|exact|neural|lumped  wrapping (Type III) muscles: smooth (default) gives them\n"
         "                       mass over the analytic smooth wrap model (C2 across contact changes,\n"
         "                       energy-consistent); exact over OpenSim's wrapping with finite-difference\n"
         "                       Jacobians (energy jumps at contact changes); neural over a trained network;\n"
         "                       lumped keeps them massless. smooth takes paths with at most one wrap\n"
         "                       object per segment over the surfaces it supports, exact any path OpenSim\n"
         "                       wraps; other wrapping muscles stay lumped and the summary says why\n"
         "                       (\"wrapping (Type III): W of N carry mass\"). Simbody engines take the\n"
         "                       same paths except exact beyond origin -> one wrap -> insertion, and name\n"
         "                       the muscles they refuse\n"
         "  --wrap-width W       smooth (and neural's fallback): transition width in metres (default 0.05\n"
         "                       of the radius)\n"
         "  --wrap-network FILE  neural (required): a network of `redmax train-wrap` (e.g.\n"
         "                       osim_models/networks/cylinder_3x64.txt); surfaces it was not trained for\n"
         "                       and inputs outside its training box use the smooth model, with a warning\n"
         "                       once per muscle and the count in the summary\n"
         "The run prints every affected body's mass before and after and every muscle's mass and point\n"
         "count on stderr (not with --quiet).\n";
}

}  // namespace redmax::cli
