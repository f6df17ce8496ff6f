// The diff_drive plugin library: the `diff_drive` driver.
#include "diff_drive.hpp"

SSX_PLUGIN(SSX_DRIVER(ssx::ground::DiffDrive, "diff_drive"));
