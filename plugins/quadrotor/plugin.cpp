// The quadrotor plugin library: the `quadrotor` driver.
#include "quadrotor_driver.hpp"

SSX_PLUGIN(SSX_DRIVER(ssx::quadrotor::QuadrotorDriver, "quadrotor"));
