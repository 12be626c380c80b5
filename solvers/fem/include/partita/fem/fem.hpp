#pragma once
// Everything of partita::fem in one include.
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/gmsh_reader.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/solver.hpp"
#include "partita/fem/vtu_writer.hpp"
