#include "cli/muscle_mass_flags.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <regex>
#include <stdexcept>

#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/network_set.hpp"
#include "validation/simulate/simulate.hpp"

#ifndef REDMAX_SOURCE_DIR
#define REDMAX_SOURCE_DIR ""
#endif

namespace redmax::cli {

std::string WrapFlags::firstGiven() const {
  return hasModel() ? "--wrap" : hasWidth() ? "--wrap-width" : hasNetwork() ? "--wrap-network" : "";
}

void addWrapFlags(CLI::App& app, WrapFlags& f, bool with_model, const std::string& group) {
  if (with_model)
    f.model_opt = app.add_option("--wrap", f.model,
                                 "wrapping (Type III) muscles with mass: smooth (default) over the analytic\n"
                                 "smooth wrap model (C2 across contact changes, energy-consistent); exact\n"
                                 "over OpenSim's wrapping with finite-difference Jacobians (energy jumps\n"
                                 "at contact changes); neural over a trained network; lumped keeps them\n"
                                 "massless. smooth takes paths with up to three wrap objects per segment\n"
                                 "over the surfaces it supports, exact any path OpenSim wraps; other\n"
                                 "wrapping muscles stay lumped and the summary says why (\"wrapping\n"
                                 "(Type III): W of N carry mass\"). Simbody engines take the same paths")
                      ->type_name("smooth|exact|neural|lumped")
                      ->check(oneOf({"smooth", "exact", "neural", "lumped"}))
                      ->group(group);
  f.width_opt = app.add_option("--wrap-width", f.width,
                               "smooth (and neural's fallback): transition width in metres\n"
                               "(default 0.05 of the surface size)")
                    ->type_name("W")
                    ->check(positive("number of metres"))
                    ->group(group);
  f.network_opt = app.add_option("--wrap-network", f.network,
                                 "neural: a network of `redmax train-wrap`, a manifest\n"
                                 "(redmax-wrap-networks 1: one network per wrap object) or a folder\n"
                                 "holding wrap_networks.txt (`redmax train-wrap --for MODEL.osim --out\n"
                                 "DIR`); default: the committed osim_models/networks/wrap_networks.txt.\n"
                                 "Surfaces without a network and inputs outside a network's training box\n"
                                 "use the smooth model, with a warning once per muscle and the count in\n"
                                 "the summary")
                      ->type_name("FILE|MANIFEST|DIR")
                      ->group(group);
}

void addMuscleMassFlags(CLI::App& app, MuscleMassFlags& f) {
  const std::string g = "Muscle mass";
  f.source_opt = app.add_option("--muscle-mass", f.source,
                                "none (default: the model as OpenSim sees it, muscles lumped into the\n"
                                "bones); physiological: each muscle gets density * (max_isometric_force /\n"
                                "specific tension) * optimal_fiber_length, taken from the bodies it was\n"
                                "lumped into (total mass and centre of mass unchanged); transfer: a\n"
                                "fraction of one body's mass moves into the muscles with a path point on it")
                     ->type_name("none|physiological|transfer")
                     ->check(oneOf({"none", "physiological", "transfer"}))
                     ->group(g);
  f.muscles_opt = app.add_option("--muscles", f.muscles,
                                 "which muscles get mass: all (default), a REGEX matching whole names,\n"
                                 "or top:K, the K largest ||M_muscle|| / ||M_skeleton|| over the trial")
                      ->type_name("all|REGEX|top:K")
                      ->group(g);
  f.mass_points_opt = app.add_option("--mass-points", f.mass_points, "points per muscle (default 20)")
                          ->type_name("N")
                          ->check(between(1, 100000, true))
                          ->group(g);
  f.region_opt = app.add_option("--mass-region", f.region,
                                "points in the fibre part of the path (fibre, default; also 'fiber') or\n"
                                "along all of it (whole)")
                     ->type_name("fibre|whole")
                     ->check(oneOf({"fibre", "fiber", "whole"}))
                     ->group(g);
  f.placement_opt = app.add_option("--mass-placement", f.placement,
                                   "uniform (default): points at fixed fractions of the whole path, equal\n"
                                   "strain in fibre and tendon, as the dissertation; fibre: points follow the\n"
                                   "fibre, the tendon keeping its own length (rigid: slack length; elastic:\n"
                                   "from the fibre-length state, or equilibrium without states). Muscles\n"
                                   "without a modelled class, wrapping or with a tendon-force state stay uniform")
                         ->type_name("uniform|fibre")
                         ->check(oneOf({"uniform", "fibre", "fiber"}))
                         ->group(g);
  f.tension_opt = app.add_option("--specific-tension", f.specific_tension,
                                 "Pa; default 600000 (60 N/cm^2, Rajagopal et al. 2016)")
                      ->type_name("PA")
                      ->check(positive())
                      ->group(g);
  f.density_opt = app.add_option("--muscle-density", f.density, "kg/m^3; default 1059.7 (Ward & Lieber 2005)")
                      ->type_name("KG_M3")
                      ->check(positive())
                      ->group(g);
  f.body_opt = app.add_option("--transfer-body", f.transfer_body, "transfer only: the body that gives mass")
                   ->type_name("BODY")
                   ->group(g);
  f.fraction_opt = app.add_option("--transfer-fraction", f.transfer_fraction,
                                  "transfer only: the fraction F in [0, 1) of its mass that moves")
                       ->type_name("F")
                       ->check(number())
                       ->group(g);
  addWrapFlags(app, f.wrap, true, g);
}

std::string defaultWrapNetworksPath() {
  const std::filesystem::path p =
      std::filesystem::path(REDMAX_SOURCE_DIR) / "osim_models" / "networks" / wrapNetworkManifestName();
  std::error_code ec;
  return *REDMAX_SOURCE_DIR && std::filesystem::is_regular_file(p, ec) ? p.string() : "";
}

void parseWrapFlags(const WrapFlags& f, osim::MuscleMassOptions& o) {
  // smooth by default: the mass matrix stays continuous at contact changes, so energy is conserved
  // to integrator error; exact (finite-difference J) jumps there [D Sec. 5.3.3, 6.2.4]
  const std::string& model = f.model;
  o.wrap = WrapMassOptions{};
  o.wrap_mass = model != "lumped";
  if (model == "smooth") {
    o.wrap.model = WrapModel::Smooth;
  } else if (model == "exact") {
    o.wrap.model = WrapModel::Exact;
  } else if (model == "neural") {
    o.wrap.model = WrapModel::Neural;
    std::string path = f.network;
    if (!f.hasNetwork()) {
      // the committed networks (osim_models/networks/wrap_networks.txt), said so
      path = defaultWrapNetworksPath();
      if (path.empty())
        throw UsageError{"--wrap neural needs --wrap-network FILE|MANIFEST|DIR (no committed networks found under " +
                         std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks)"};
      std::cerr << "note: --wrap neural without --wrap-network: using the committed networks " << path << "\n";
    } else if (path.empty()) {
      throw UsageError{"--wrap-network needs a network file, a manifest or a folder"};
    }
    try {
      loadWrapNetworks(path).applyTo(o.wrap);
    } catch (const NetworkFormatError& e) {
      throw UsageError{e.what()};  // FILE:LINE: first
    } catch (const std::exception& e) {
      throw UsageError{std::string("--wrap-network: ") + e.what()};
    }
  } else if (model != "lumped") {
    throw UsageError{"--wrap must be smooth, exact, neural or lumped, got '" + model + "'"};
  }
  if (f.hasWidth()) {
    if (model != "smooth" && model != "neural")
      throw UsageError{"--wrap-width needs --wrap smooth or neural (the smooth model's transition width; neural "
                       "falls back to it)"};
    o.wrap.width = f.width;
  }
  if (f.hasNetwork() && model != "neural") throw UsageError{"--wrap-network needs --wrap neural"};
}

std::shared_ptr<WrapFallbackMonitor> makeWrapFallbackMonitor(const WrapFlags& f) {
  if (f.model != "neural") return nullptr;
  // outside the training box the smooth model takes over: warn once per muscle, count them all
  return std::make_shared<WrapFallbackMonitor>(
      [](const std::string& message) { std::cerr << "warning: " << message << "\n"; });
}

osim::MuscleMassOptions parseMuscleMassFlags(const MuscleMassFlags& f, bool fraction_from_sweep) {
  using Source = osim::MuscleMassOptions::Source;
  osim::MuscleMassOptions o;
  try {
    o.source = osim::parseMuscleMassSource(f.source);
  } catch (const std::invalid_argument& e) {
    throw UsageError{e.what()};
  }
  const std::vector<std::pair<const CLI::Option*, const char*>> needs_source = {
      {f.muscles_opt, "--muscles"},          {f.mass_points_opt, "--mass-points"},
      {f.region_opt, "--mass-region"},       {f.placement_opt, "--mass-placement"},
      {f.tension_opt, "--specific-tension"},
      {f.density_opt, "--muscle-density"},   {f.body_opt, "--transfer-body"},
      {f.fraction_opt, "--transfer-fraction"}, {f.wrap.model_opt, "--wrap"},
      {f.wrap.width_opt, "--wrap-width"},    {f.wrap.network_opt, "--wrap-network"}};
  if (o.source == Source::None) {
    for (const auto& [opt, name] : needs_source)
      if (opt && opt->count() > 0) throw UsageError{std::string(name) + " needs --muscle-mass physiological or transfer"};
    return o;
  }
  parseWrapFlags(f.wrap, o);
  if (o.source != Source::Transfer)
    for (const auto& [opt, name] : {std::pair{f.body_opt, "--transfer-body"}, std::pair{f.fraction_opt, "--transfer-fraction"}})
      if (opt->count() > 0) throw UsageError{std::string(name) + " needs --muscle-mass transfer"};

  o.muscles = f.muscles;
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
  o.mass_points = static_cast<int>(f.mass_points);
  o.region = f.region == "whole" ? MassPointOptions::Region::WholePath : MassPointOptions::Region::Fibre;
  o.placement = f.placement == "uniform" ? osim::MuscleMassOptions::Placement::Uniform
                                         : osim::MuscleMassOptions::Placement::Fibre;
  if (o.placement == osim::MuscleMassOptions::Placement::Fibre && o.region == MassPointOptions::Region::WholePath)
    throw UsageError{"--mass-placement fibre spreads the points over the fibre; it excludes --mass-region whole"};
  o.specific_tension = f.specific_tension;
  o.density = f.density;

  if (o.source == Source::Transfer) {
    if (f.body_opt->count() == 0 || f.transfer_body.empty())
      throw UsageError{"--muscle-mass transfer needs --transfer-body BODY"};
    o.transfer_body = f.transfer_body;
    if (!fraction_from_sweep) {
      if (f.fraction_opt->count() == 0) throw UsageError{"--muscle-mass transfer needs --transfer-fraction F"};
      o.transfer_fraction = f.transfer_fraction;
      if (!(o.transfer_fraction >= 0.0 && o.transfer_fraction < 1.0))
        throw UsageError{"--transfer-fraction must be in [0, 1), got " + f.fraction_opt->as<std::string>()};
    }
  }
  return o;
}

const char* muscleMassFooter() {
  return "Muscle mass is taken from the bodies it was lumped into, so the model's total mass never changes;\n"
         "the run prints every affected body's mass before and after and every muscle's mass and point\n"
         "count on stderr (not with --quiet).\n";
}

namespace {

// --muscle-mass-kg NAME=KG,NAME=KG
std::vector<std::pair<std::string, double>> parseMassList(const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  for (const std::string& item : splitList(text, ",")) {
    const auto eq = item.find('=');
    double kg = 0.0;
    bool ok = eq != std::string::npos && eq > 0;
    if (ok) {
      try {
        size_t used = 0;
        kg = std::stod(item.substr(eq + 1), &used);
        ok = used == item.size() - eq - 1 && std::isfinite(kg) && kg >= 0.0;
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok) throw UsageError{"--muscle-mass-kg expects NAME=KG[,NAME=KG...] with KG >= 0, got '" + item + "'"};
    out.push_back({item.substr(0, eq), kg});
  }
  if (out.empty()) throw UsageError{"--muscle-mass-kg expects NAME=KG[,NAME=KG...]"};
  return out;
}

}  // namespace

void applyMuscleMassOptions(const CLI::App& app, const MuscleMassFlags& mm, const std::string& muscle_mass_kg,
                            validation::SimulationModelOptions& mo) {
  // --wrap and friends (muscle_mass_flags.hpp) choose how wrapping muscles with mass move; with no
  // mass at all they would do nothing
  if (mm.wrap.any() && !given(app, "--muscle-mass-kg") && mm.source == "none")
    throw UsageError{mm.wrap.firstGiven() +
                     " needs muscle mass (--muscle-mass physiological|transfer or --muscle-mass-kg)"};

  if (given(app, "--muscle-mass-kg")) {
    // explicit masses take the point count and region from --mass-points / --mass-region; the
    // flags that choose or size a mass source do not apply
    if (mm.source != "none") throw UsageError{"--muscle-mass-kg excludes --muscle-mass " + mm.source};
    for (const char* n : {"--muscles", "--specific-tension", "--muscle-density", "--transfer-body", "--transfer-fraction"})
      if (given(app, n)) throw UsageError{std::string(n) + " needs --muscle-mass physiological or transfer"};
    mo.explicit_masses = parseMassList(muscle_mass_kg);
    parseWrapFlags(mm.wrap, mo.muscle_mass);
    mo.muscle_mass.mass_points = static_cast<int>(mm.mass_points);
    if (mm.region == "whole") mo.muscle_mass.region = MassPointOptions::Region::WholePath;
    if (mm.placement != "uniform") {
      if (mo.muscle_mass.region == MassPointOptions::Region::WholePath)
        throw UsageError{"--mass-placement fibre spreads the points over the fibre; it excludes --mass-region whole"};
      mo.muscle_mass.placement = osim::MuscleMassOptions::Placement::Fibre;
    }
  } else {
    mo.muscle_mass = parseMuscleMassFlags(mm);
  }
}

}  // namespace redmax::cli
