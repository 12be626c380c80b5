#pragma once
// Everything of partita::fem in one include.
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/gmsh_reader.hpp"
#include "partita/fem/hardening_curve.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/state_io.hpp"
#include "partita/fem/structural_solver.hpp"
#include "partita/fem/vtu_writer.hpp"
