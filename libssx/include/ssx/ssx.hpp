#pragma once
/// @file
/// The whole public API of libssx.

#include <ssx/artifact.hpp>
#include <ssx/class_loader.hpp>
#include <ssx/command.hpp>
#include <ssx/descriptor.hpp>
#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/hash.hpp>
#include <ssx/export.hpp>
#include <ssx/measurements.hpp>
#include <ssx/metrics.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/parameters.hpp>
#include <ssx/plugin.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/random.hpp>
#include <ssx/render.hpp>
#include <ssx/scene.hpp>
#include <ssx/scene_model.hpp>
#include <ssx/setpoint.hpp>
#include <ssx/state.hpp>
#include <ssx/timing.hpp>
#include <ssx/types.hpp>
#include <ssx/version.hpp>
