#pragma once
// Moved: the ISO 230-4 evaluation is general and lives in cnccomp/circular_test.hpp.
#include "cnccomp/circular_test.hpp"
