#include "converter/analyze/states_file.hpp"

#include <limits>
#include <set>

#include "converter/coordinates_file.hpp"
#include "converter/detail/xml_util.hpp"

namespace redmax::osim {

AnalyzeStatesFile::AnalyzeStatesFile(const std::string& path) : path_(path), table_(readStorage(path)) {
  if (table_.numRows() == 0) throw ConvertError(path, table_.label_line, "the states file has no rows");
}

Storage AnalyzeStatesFile::coordinatesTable() const {
  Storage s = table_;
  for (std::string& l : s.labels) {
    const std::string suffix = "/value";
    if (l.size() <= suffix.size() || l.compare(l.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
    const std::string head = l.substr(0, l.size() - suffix.size());
    const size_t slash = head.rfind('/');
    l = slash == std::string::npos ? head : head.substr(slash + 1);
  }
  return s;
}

void AnalyzeStatesFile::bind(const ModelDescription& d, const Model& skeleton, const std::vector<int>& coordinate_desc,
                             const MusculoskeletalModel& geometry, std::vector<std::string>& warnings) {
  const int nr = skeleton.nr();
  value_col_.assign(static_cast<size_t>(nr), -1);
  speed_col_.assign(static_cast<size_t>(nr), -1);
  scale_.assign(static_cast<size_t>(nr), 1.0);
  std::set<int> used;
  std::vector<std::string> no_speed, no_value;
  for (int k = 0; k < nr; ++k) {
    const int ci = coordinate_desc[static_cast<size_t>(k)];
    if (ci < 0) continue;
    const CoordinateDesc& c = d.coordinates[static_cast<size_t>(ci)];
    value_col_[k] = findCoordinateColumn(table_, c);
    speed_col_[k] = findSpeedColumn(table_, c);
    scale_[k] = coordinateScale(table_, c);
    if (value_col_[k] >= 0) used.insert(value_col_[k]);
    else no_value.push_back(c.name);
    if (speed_col_[k] >= 0) used.insert(speed_col_[k]);
    else no_speed.push_back(c.name);
  }
  muscle_col_.clear();
  muscle_state_columns_ = 0;
  for (size_t m = 0; m < geometry.muscles().size(); ++m) {
    std::vector<int> cols;
    if (const auto& model = geometry.muscleModels()[m]) {
      const std::string& name = geometry.muscles()[m].name;
      for (const std::string& st : model->stateNames()) {
        int c = table_.findColumn("/forceset/" + name + "/" + st);
        if (c < 0) c = table_.findColumn(name + "." + st);  // OpenSim 3
        if (c >= 0) {
          used.insert(c);
          ++muscle_state_columns_;
        }
        cols.push_back(c);
      }
    }
    muscle_col_.push_back(cols);
  }
  if (!no_value.empty())
    warnings.push_back(path_ + ": no value column for " + detail::joinNames(no_value) +
                       ": held at the default value, as OpenSim does");
  if (!no_speed.empty())
    warnings.push_back(path_ + ": no speed column for " + detail::joinNames(no_speed) + ": u = 0, as OpenSim does");
  std::vector<std::string> unused;
  for (int c = 0; c < table_.numColumns(); ++c)
    if (!used.count(c)) unused.push_back(table_.labels[static_cast<size_t>(c)]);
  if (!unused.empty())
    warnings.push_back(path_ + ": columns that name no state of the model are not used: " + detail::joinNames(unused));
}

void AnalyzeStatesFile::stateAt(int r, const VecX& default_q, VecX& q, VecX& u) const {
  const int nr = static_cast<int>(value_col_.size());
  q = default_q;
  u = VecX::Zero(nr);
  for (int k = 0; k < nr; ++k) {
    if (value_col_[k] >= 0) q[k] = table_.data(r, value_col_[k]) * scale_[k];
    if (speed_col_[k] >= 0) u[k] = table_.data(r, speed_col_[k]) * scale_[k];
  }
}

std::vector<double> AnalyzeStatesFile::speedColumn(int k) const {
  std::vector<double> u(static_cast<size_t>(table_.numRows()), 0.0);
  if (speed_col_[static_cast<size_t>(k)] >= 0)
    for (int r = 0; r < table_.numRows(); ++r) u[static_cast<size_t>(r)] = table_.data(r, speed_col_[k]) * scale_[k];
  return u;
}

std::vector<std::vector<double>> AnalyzeStatesFile::muscleStatesAt(int r) const {
  std::vector<std::vector<double>> z(muscle_col_.size());
  for (size_t m = 0; m < muscle_col_.size(); ++m)
    for (int c : muscle_col_[m])
      z[m].push_back(c >= 0 ? table_.data(r, c) : std::numeric_limits<double>::quiet_NaN());
  return z;
}

}  // namespace redmax::osim
