#include "engine/detect.h"
