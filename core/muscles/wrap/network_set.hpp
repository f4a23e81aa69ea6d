#pragma once
// Wrap-network manifests (issue 22): one text file naming the networks of a model, one per wrap
// object, and defaults per surface type, so that `--wrap neural` can give every wrap object the
// network trained on the inputs it sees (`redmax train-wrap --for MODEL.osim` writes one).
//
// Format (text; '#' starts a comment line, blank lines ignored; FILE paths relative to the
// manifest's folder, no spaces):
//   redmax-wrap-networks 1
//   wrap WRAP_OBJECT FILE      the network of the wrap object of that name (OpenSim WrapObject name)
//   surface TYPE FILE          the network of every other surface of TYPE (cylinder, sphere, ...)
// A name or a type listed twice, an unknown keyword, a missing field or a network file that does not
// load is an error naming the manifest's line ("FILE:LINE: ..."; for a bad network file its own
// FILE:LINE follows).
#include <map>
#include <memory>
#include <string>

#include "core/muscles/wrap/network.hpp"

namespace redmax {

struct WrapMassOptions;

/// The networks a manifest (or a single file) names, loaded and checked (loadWrapNetwork).
struct WrapNetworkSet {
  std::map<std::string, std::shared_ptr<const Mlp>> by_wrap;  ///< wrap object name -> network
  std::map<std::string, std::shared_ptr<const Mlp>> by_type;  ///< wrapTypeName -> network
  std::map<std::string, std::string> files;                   ///< "wrap NAME" / "surface TYPE" -> file read
  std::shared_ptr<const Mlp> single;  ///< a plain network file given instead of a manifest
  std::string source;                 ///< the manifest or network file read
  /// into options.network, options.wrap_networks and options.type_networks
  void applyTo(WrapMassOptions& options) const;
};

/// The manifest's conventional file name inside a folder ("wrap_networks.txt").
const char* wrapNetworkManifestName();

/// True when `path` is a file whose first line (after comments) starts "redmax-wrap-networks".
bool isWrapNetworkManifest(const std::string& path);

/// Parse a manifest's text; `folder` resolves its relative FILEs. NetworkFormatError ("SOURCE:LINE:
/// ...") for any malformed line or any network that does not load.
WrapNetworkSet parseWrapNetworkManifest(const std::string& text, const std::string& source, const std::string& folder);

/// A network file, a manifest, or a folder holding wrapNetworkManifestName(). NetworkFormatError
/// for a malformed file, std::runtime_error for a path that does not exist or cannot be read.
WrapNetworkSet loadWrapNetworks(const std::string& path);

}  // namespace redmax
