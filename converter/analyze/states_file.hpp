#pragma once
// An AnalyzeTool states_file (docs/analyze.md, "States file"): a states table as OpenSim writes it, with
// OpenSim 4 state names (/jointset/J/C/value, /jointset/J/C/speed, /forceset/M/activation,
// /forceset/M/fiber_length, ...) or OpenSim 3's (C, C_u, M.activation, M.fiber_length). Each row is
// one state: AnalyzeTool::run sets q, u and the muscles' states from it, without filtering (the
// low-pass cutoff applies to coordinates files only).
//
// Two steps, because the inverse-dynamics tool that reads the model needs the coordinates first:
// read() and coordinatesTable() (the value columns relabelled by coordinate name, so the tool's
// exact-name match takes them; units unchanged), then bind() to the built model, which maps each
// core coordinate's value and speed column and each muscle state's column.
#include <string>
#include <vector>

#include "converter/model_description.hpp"
#include "converter/storage.hpp"
#include "core/model/musculoskeletal_model.hpp"

namespace redmax::osim {

class AnalyzeStatesFile {
 public:
  /// Reads the file. Throws ConvertError for a malformed table or one with no rows.
  explicit AnalyzeStatesFile(const std::string& path);

  const std::string& path() const { return path_; }
  const Storage& table() const { return table_; }
  /// the table with each /.../C/value (or .../C/value) label renamed C
  Storage coordinatesTable() const;

  /// Map the columns: core coordinate k of `skeleton` (description index coordinate_desc[k], -1
  /// when it has none) and every muscle of `geometry` (its model's stateNames()). Columns the
  /// file has that name nothing of the model, and coordinates without a speed column (u = 0,
  /// OpenSim's default), are appended to warnings.
  void bind(const ModelDescription& d, const Model& skeleton, const std::vector<int>& coordinate_desc,
            const MusculoskeletalModel& geometry, std::vector<std::string>& warnings);

  /// q and u (core order, SI) of row r; a coordinate without a value column keeps default_q[k]
  void stateAt(int r, const VecX& default_q, VecX& q, VecX& u) const;
  /// core coordinate k's speed (SI) at every row; zeros without a speed column
  std::vector<double> speedColumn(int k) const;
  /// the muscles' states of row r: [muscle][state], nan where the file has no column
  std::vector<std::vector<double>> muscleStatesAt(int r) const;
  /// the states the file gives, as "muscle/state" (for reports)
  int numMuscleStateColumns() const { return muscle_state_columns_; }

 private:
  std::string path_;
  Storage table_;
  std::vector<int> value_col_, speed_col_;
  std::vector<double> scale_;
  std::vector<std::vector<int>> muscle_col_;
  int muscle_state_columns_ = 0;
};

}  // namespace redmax::osim
