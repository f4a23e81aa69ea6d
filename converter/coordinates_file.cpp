#include "converter/coordinates_file.hpp"

namespace redmax::osim {
namespace {

// the '/'-separated elements of a label: "/jointset/j/q/value" -> {jointset, j, q, value}
std::vector<std::string> pathElements(const std::string& label) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : label) {
    if (c == '/') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

}  // namespace

double degreesToRadians() {
  // SimTK_DEGREE_TO_RADIAN is computed in long double and used as a double
  return static_cast<double>(3.14159265358979323846264338327950288L / 180.0L);
}

std::string coordinatePath(const CoordinateDesc& c) { return "/jointset/" + c.joint + "/" + c.name; }

bool labelIsCoordinatePath(const std::string& label, const CoordinateDesc& c) {
  if (label.find('/') == std::string::npos) return false;
  const std::vector<std::string> el = pathElements(label);
  if (el.empty()) return false;
  if (el.back() == c.name) return true;
  return el.size() >= 2 && el.back() == "value" && el[el.size() - 2] == c.name;
}

int findCoordinateColumn(const Storage& table, const CoordinateDesc& c, CoordinateLabels rule) {
  int k = table.findColumn(c.name);
  if (k >= 0 || rule == CoordinateLabels::ExactName) return k;
  k = table.findColumn(coordinatePath(c) + "/value");
  if (k >= 0) return k;
  for (int j = 0; j < table.numColumns(); ++j)
    if (labelIsCoordinatePath(table.labels[j], c)) return j;
  return -1;
}

int findSpeedColumn(const Storage& table, const CoordinateDesc& c) {
  int k = table.findColumn(coordinatePath(c) + "/speed");
  if (k >= 0) return k;
  for (int j = 0; j < table.numColumns(); ++j) {
    const std::string& l = table.labels[j];
    if (l.find('/') == std::string::npos) continue;
    const std::vector<std::string> el = pathElements(l);
    if (el.size() >= 2 && el.back() == "speed" && el[el.size() - 2] == c.name) return j;
  }
  return table.findColumn(c.name + "_u");
}

double coordinateScale(const Storage& table, const CoordinateDesc& c) {
  return table.in_degrees && c.motion_type == MotionType::Rotational ? degreesToRadians() : 1.0;
}

CoordinateColumns matchCoordinateColumns(const Storage& table, const std::vector<CoordinateDesc>& coordinates,
                                         CoordinateLabels rule) {
  CoordinateColumns m;
  for (const CoordinateDesc& c : coordinates) {
    const int k = findCoordinateColumn(table, c, rule);
    m.value_column.push_back(k);
    m.scale.push_back(coordinateScale(table, c));
    m.matched += k >= 0 ? 1 : 0;
  }
  if (rule == CoordinateLabels::ExactName)
    for (const std::string& label : table.labels) {
      bool exact = false, path = false;
      for (const CoordinateDesc& c : coordinates) {
        exact = exact || label == c.name;
        path = path || labelIsCoordinatePath(label, c);
      }
      if (path && !exact) m.unused_path_labels.push_back(label);
    }
  return m;
}

}  // namespace redmax::osim
