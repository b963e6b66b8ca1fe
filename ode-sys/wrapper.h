/* Everything bindgen sees: the public ODE API and our message shim. */
#include <ode/ode.h>
#include "shim/ode_shim.h"
