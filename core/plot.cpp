#include "core/plot.h"
