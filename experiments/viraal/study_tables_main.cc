/// @file
/// orbed-study-tables: the ViRAAl study's files from its runs' results.json (what, flags and exit
/// codes: experiments/viraal/study_tables.h). Publishes and subscribes nothing.
#include <iostream>

#include "experiments/viraal/study_tables.h"

int main(int argc, char** argv) { return orbed::study::RunStudyTables(argc, argv, std::cout, std::cerr); }
