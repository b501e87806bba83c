#include "comparisons/mesh_io.h"
