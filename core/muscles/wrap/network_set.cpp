#include "core/muscles/wrap/network_set.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/geometry/wrap_surface.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/wrap/network_model.hpp"

namespace redmax {
namespace fs = std::filesystem;

namespace {

std::string readText(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot open");
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// the first line that is neither blank nor a comment
std::string firstLine(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto p = line.find_first_not_of(" \t\r");
    if (p == std::string::npos || line[p] == '#') continue;
    return line.substr(p);
  }
  return "";
}

}  // namespace

void WrapNetworkSet::applyTo(WrapMassOptions& o) const {
  o.network = single;
  o.wrap_networks = by_wrap;
  o.type_networks = by_type;
}

const char* wrapNetworkManifestName() { return "wrap_networks.txt"; }

bool isWrapNetworkManifest(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  std::ifstream f(path, std::ios::binary);
  std::string head(4096, '\0');
  f.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(f.gcount()));
  return firstLine(head).rfind("redmax-wrap-networks", 0) == 0;
}

WrapNetworkSet parseWrapNetworkManifest(const std::string& text, const std::string& source, const std::string& folder) {
  WrapNetworkSet set;
  set.source = source;
  std::istringstream in(text);
  std::string line;
  int no = 0;
  bool header = false;
  auto fail = [&](const std::string& msg) { throw NetworkFormatError(source + ":" + std::to_string(no) + ": " + msg); };
  while (std::getline(in, line)) {
    ++no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::vector<std::string> w;
    for (std::string t; ls >> t;) w.push_back(t);
    if (w.empty() || w[0][0] == '#') continue;
    if (!header) {
      if (w[0] != "redmax-wrap-networks") fail("expected the header 'redmax-wrap-networks 1', found '" + w[0] + "'");
      if (w.size() != 2 || w[1] != "1") fail("unsupported manifest version (this reader knows 'redmax-wrap-networks 1')");
      header = true;
      continue;
    }
    if (w[0] != "wrap" && w[0] != "surface")
      fail("unknown keyword '" + w[0] + "' (expected 'wrap WRAP_OBJECT FILE' or 'surface TYPE FILE')");
    if (w.size() != 3) fail("'" + w[0] + "' takes a name and a file, got " + std::to_string(w.size() - 1) + " fields");
    if (w[0] == "surface") {
      try {
        parseWrapType(w[1]);
      } catch (const std::exception&) {
        fail("unknown surface type '" + w[1] + "' (cylinder, sphere, ellipsoid or torus)");
      }
    }
    const std::string key = w[0] + " " + w[1];
    if (set.files.count(key)) fail("'" + key + "' is listed twice");
    const fs::path file = fs::path(w[2]).is_absolute() ? fs::path(w[2]) : fs::path(folder) / w[2];
    std::shared_ptr<const Mlp> net;
    try {
      net = loadWrapNetwork(file.string());
    } catch (const std::exception& e) {
      fail("network '" + w[2] + "': " + e.what());
    }
    if (w[0] == "surface") {
      if (auto it = net->meta.find("surface"); it != net->meta.end() && it->second != w[1])
        fail("network '" + w[2] + "' is a " + it->second + " network, listed for " + w[1]);
      set.by_type[w[1]] = net;
    } else {
      set.by_wrap[w[1]] = net;
    }
    set.files[key] = file.string();
  }
  if (!header) {
    no = std::max(no, 1);
    fail("empty manifest: expected the header 'redmax-wrap-networks 1'");
  }
  if (set.files.empty()) fail("the manifest lists no network");
  return set;
}

WrapNetworkSet loadWrapNetworks(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path m = fs::path(path) / wrapNetworkManifestName();
    if (!fs::is_regular_file(m, ec))
      throw std::runtime_error(path + ": folder without a manifest " + wrapNetworkManifestName() +
                               " (`redmax train-wrap --for MODEL.osim --out DIR` writes one)");
    return parseWrapNetworkManifest(readText(m.string()), m.string(), path);
  }
  if (!fs::exists(path, ec)) throw std::runtime_error(path + ": no such file or folder");
  if (isWrapNetworkManifest(path))
    return parseWrapNetworkManifest(readText(path), path, fs::path(path).parent_path().string());
  WrapNetworkSet set;
  set.source = path;
  set.single = loadWrapNetwork(path);
  return set;
}

}  // namespace redmax
