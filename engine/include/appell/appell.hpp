// Everything the engine offers, in one include.
#pragma once

#include <appell/spatial.hpp>
#include <appell/model.hpp>
#include <appell/data.hpp>
#include <appell/configuration.hpp>
#include <appell/kinematics.hpp>
#include <appell/dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/constraint.hpp>
#include <appell/constraint_set.hpp>
