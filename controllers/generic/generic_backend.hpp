#pragma once
// Backend "generic" (see generic_backend.cpp): emit with an explicit grid-map tolerance (the registered backend uses
// the defaults of GridMapOptions).
#include "controllers/backend.hpp"
#include "controllers/generic/grid_map.hpp"

namespace cnccomp::controllers::generic {

EmitResult emitFiles(const EmitRequest& request, const GridMapOptions& options);

}  // namespace cnccomp::controllers::generic
