#pragma once
// The MUSCLE-MASS OPTIONS of docs/commands.md §1, declared once here and added to every command
// that builds a model with muscle mass (`redmax id`, `simulate`, `validate`, ...):
//   --muscle-mass none|physiological|transfer   (default none)
//   --muscles all|REGEX|top:K   --mass-points N   --mass-region fibre|whole
//   --mass-placement uniform|fibre
//   --specific-tension PA       --muscle-density KG_M3
//   --transfer-body BODY        --transfer-fraction F
//   --wrap smooth|exact|neural|lumped  --wrap-width W  --wrap-network FILE
//     the wrap model of wrapping (Type III) muscles with mass. Default smooth: every command that
//     builds muscle mass gives wrapping muscles of a supported shape (core/muscles/wrap_muscle.hpp)
//     their mass over the smooth model (C2 across contact changes, so energy-consistent); exact and
//     neural are the dissertation's routes; lumped keeps them massless.
// Meanings and defaults: converter/build/muscle_mass.hpp.
#include <memory>
#include <string>

#include "cli/flags.hpp"
#include "converter/build/muscle_mass.hpp"
#include "core/muscles/wrap/network_model.hpp"

namespace redmax::validation {
struct SimulationModelOptions;
}

namespace redmax::cli {

/// --wrap, --wrap-width, --wrap-network: values as given, and whether each was given.
struct WrapFlags {
  std::string model = "smooth";  ///< --wrap (`redmax lengths` declares its own, default exact)
  double width = 0.0;            ///< --wrap-width (m)
  std::string network;           ///< --wrap-network FILE
  CLI::Option* model_opt = nullptr;
  CLI::Option* width_opt = nullptr;
  CLI::Option* network_opt = nullptr;

  bool hasModel() const { return model_opt && model_opt->count() > 0; }
  bool hasWidth() const { return width_opt && width_opt->count() > 0; }
  bool hasNetwork() const { return network_opt && network_opt->count() > 0; }
  /// true when any of --wrap, --wrap-width, --wrap-network is given
  bool any() const { return hasModel() || hasWidth() || hasNetwork(); }
  /// the first of them given ("--wrap", "--wrap-width", "--wrap-network"), for messages
  std::string firstGiven() const;
};

/// The muscle-mass flags of one command: values as given, and whether each was given.
struct MuscleMassFlags {
  std::string source = "none";
  std::string muscles = "all";
  long mass_points = 20;
  std::string region = "fibre";
  std::string placement = "uniform";
  double specific_tension = osim::MuscleMassOptions{}.specific_tension;
  double density = osim::MuscleMassOptions{}.density;
  std::string transfer_body;
  double transfer_fraction = 0.0;
  WrapFlags wrap;
  CLI::Option* source_opt = nullptr;
  CLI::Option* muscles_opt = nullptr;
  CLI::Option* mass_points_opt = nullptr;
  CLI::Option* region_opt = nullptr;
  CLI::Option* placement_opt = nullptr;
  CLI::Option* tension_opt = nullptr;
  CLI::Option* density_opt = nullptr;
  CLI::Option* body_opt = nullptr;
  CLI::Option* fraction_opt = nullptr;
};

/// Declares --wrap (when `with_model`), --wrap-width and --wrap-network on `app`, in `group`.
void addWrapFlags(CLI::App& app, WrapFlags& f, bool with_model = true, const std::string& group = "Muscle mass");

/// Declares the muscle-mass flags, the wrap flags included, on `app` (help group "Muscle mass").
void addMuscleMassFlags(CLI::App& app, MuscleMassFlags& f);

/// The options from the flags (defaults for those not given). Throws UsageError for a value out of
/// range (F outside [0, 1), a bad REGEX or top:K), for transfer without --transfer-body, and for
/// --muscles, --mass-points, --mass-region, --mass-placement, --specific-tension, --muscle-density, --transfer-*
/// given without a source that uses them (a flag that would do nothing is a mistake).
/// `fraction_from_sweep`: --transfer-fraction is not needed (`validate --mass-sweep` gives them).
osim::MuscleMassOptions parseMuscleMassFlags(const MuscleMassFlags& f, bool fraction_from_sweep = false);

/// The wrap flags alone into o.wrap_mass and o.wrap, for a source that gives mass (also `simulate
/// --muscle-mass-kg`). Not given: wrap_mass on, smooth model, default width. lumped: wrap_mass off.
/// Throws UsageError for an unknown model, a width given without smooth/neural, --wrap-network
/// without neural, or a --wrap-network that loadWrapNetworks refuses (a network file, a manifest or
/// a folder). neural sets o.wrap's networks; without --wrap-network it takes the committed
/// manifest (defaultWrapNetworksPath) and says so on stderr.
void parseWrapFlags(const WrapFlags& f, osim::MuscleMassOptions& o);

/// REDMAX_SOURCE_DIR/osim_models/networks/wrap_networks.txt when it exists, else "".
std::string defaultWrapNetworksPath();

/// --wrap neural: a WrapFallbackMonitor that warns on stderr once per muscle (the command sums the
/// counts of its workspaces into it and prints its summary()); null for the other models.
std::shared_ptr<WrapFallbackMonitor> makeWrapFallbackMonitor(const WrapFlags& f);

/// What the run prints about muscle mass, for the footer of a command's --help.
const char* muscleMassFooter();

/// The muscle mass of a model that simulate-like commands build: MUSCLE-MASS OPTIONS, or
/// `--muscle-mass-kg NAME=KG,...` (muscle_mass_kg; the command declares that flag) with its point
/// count, region, placement and wrap flags, into mo.muscle_mass and mo.explicit_masses. Throws
/// UsageError for flags that do not combine.
void applyMuscleMassOptions(const CLI::App& app, const MuscleMassFlags& mm, const std::string& muscle_mass_kg,
                            validation::SimulationModelOptions& mo);

}  // namespace redmax::cli
