// Fuzz target for the ExternalLoads reader (converter/external_loads.hpp). An input is the XML,
// optionally followed by a line "#REDMAX-DATAFILE#" and the contents of the data file, written
// beside it as data.mot (the corpus XMLs name <datafile>data.mot</datafile>). Loads that read are
// then checked against a small fixed model (checkExternalLoads).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <string_view>

#include "converter/external_loads.hpp"
#include "converter/osim_reader.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

constexpr std::string_view kSeparator = "\n#REDMAX-DATAFILE#\n";

// two bodies (a, b) under ground, for checkExternalLoads
const char kModel[] = R"(<?xml version="1.0"?>
<OpenSimDocument Version="40000">
<Model name="m">
<BodySet><objects>
<Body name="a"><mass>1</mass><mass_center>0 0 0</mass_center><inertia>1 1 1 0 0 0</inertia></Body>
<Body name="b"><mass>1</mass><mass_center>0 0 0</mass_center><inertia>1 1 1 0 0 0</inertia></Body>
</objects></BodySet>
<JointSet><objects>
<PinJoint name="ja"><socket_parent_frame>/ground</socket_parent_frame><socket_child_frame>/bodyset/a</socket_child_frame></PinJoint>
<PinJoint name="jb"><socket_parent_frame>/bodyset/a</socket_parent_frame><socket_child_frame>/bodyset/b</socket_child_frame></PinJoint>
</objects></JointSet>
</Model>
</OpenSimDocument>
)";

const std::optional<redmax::osim::ModelDescription>& model() {
  static const std::optional<redmax::osim::ModelDescription> m =
      []() -> std::optional<redmax::osim::ModelDescription> {
    try {
      const std::string p = redmax::fuzz::writeInput(
          "model.osim", reinterpret_cast<const std::uint8_t*>(kModel), std::strlen(kModel));
      return redmax::osim::readOsimModel(p);
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }();
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = in.find(kSeparator);
  const std::string_view xml = in.substr(0, cut);
  const std::string dir = redmax::fuzz::tempDir();
  const auto* xml_bytes = reinterpret_cast<const std::uint8_t*>(xml.data());
  const std::string xml_path = redmax::fuzz::writeInput("loads.xml", xml_bytes, xml.size());
  if (cut != std::string_view::npos) {
    const std::string_view body = in.substr(cut + kSeparator.size());
    redmax::fuzz::writeInput("data.mot", reinterpret_cast<const std::uint8_t*>(body.data()),
                             body.size());
  } else {
    std::remove((dir + "/data.mot").c_str());
  }
  redmax::fuzz::acceptingProjectErrors([&] {
    redmax::osim::ExternalLoads loads = redmax::osim::readExternalLoads(xml_path, dir);
    if (model()) redmax::osim::checkExternalLoads(loads, *model());
  });
  return 0;
}
