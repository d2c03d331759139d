#pragma once
/// @file
/// What every run folder holds beside a tool's own files: the provenance record (provenance.json),
/// written by scripts/orbed before a run's first process starts and finished after its last
/// (scripts/provenance.py; docs/runs.md): the commit, the command line, the settings and seeds,
/// the configuration files with their SHA-256, the hosts and the times. A results file names the
/// record of the folder it is written into, so that a copy of it still says where to look.
///
/// Threading: no shared state.

#include <string>

namespace orbed {

/// The record's file name in a run folder.
inline constexpr char kProvenanceRecord[] = "provenance.json";

/// kProvenanceRecord when `dir` holds one, else "" (a folder made without scripts/orbed: a test's,
/// or a launch started by hand).
std::string ProvenanceRecordIn(const std::string& dir);

}  // namespace orbed
