// Placeholder until the B-rep tessellation lands (issue 3).
#include "cadclash/tessellate.h"
