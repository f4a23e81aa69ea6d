#pragma once
// A demonstration of the whole report on synthetic tables, with the shape `redmax validate` will
// have once the inverse dynamics engines plug in: two engines that agree to round-off, an
// OpenSim-3.x-style reference (other column order, a column missing, an extra one, a coarser and
// shorter time grid, written to and read back from a .sto file), a three-way overlay, a mass-sweep
// section with an x-y plot and a work-precision section with a log-log plot. Every number is
// synthetic and labelled as such.
#include <string>
#include <vector>

#include "validation/report/report.hpp"

namespace redmax::validation {

struct DemoReportOptions {
  std::string gnuplot;        ///< ReportOptions::gnuplot ("" auto, "none" no plots)
  int rows = 201;             ///< rows of the engine tables over t = 0..1 s
  bool show_progress = false; ///< a progress line on stderr during the synthetic sweep
};

/// The synthetic inputs: [0] "core", [1] "simbody" (core + 1e-12 sin(6 pi t) on every column),
/// [2] "reference" (see demo_report.cpp for its exact differences).
std::vector<Table> makeDemoTables(int rows);

struct DemoReportResult {
  ReportFiles files;
  bool passed = false;
  Comparison engines;    ///< core vs simbody
  Comparison reference;  ///< core vs reference
};

/// Build and write the demonstration report into dir. Throws ReportError on I/O failure.
DemoReportResult writeDemoReport(const std::string& dir, const DemoReportOptions& opt = {});

}  // namespace redmax::validation
