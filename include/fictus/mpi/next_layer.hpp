#pragma once
// The one layer of the grid a rank reads beyond its own: the cells of its layers (Grid::cell_layer) reach
// the next layer, which the next rank holds (a periodic box's last layer is followed by layer 0).
#include "fictus/grid/grid.hpp"
#include "fictus/mpi/communicator.hpp"

namespace fictus::mpi {

/// The rank's layers (`local`, slab `slab`) followed by the next layer, from the rank that holds it; the
/// next layer is zero where there is none (after a Dirichlet box's last layer). What the slab forms of
/// the samplers over ω take (Grid::slab_index). Collective; every rank's slab is default_slab's.
template <int dim>
GridVector with_next_layer(const Grid<dim>& grid, const Slab& slab, const GridVector& local, const Communicator& comm);

}  // namespace fictus::mpi
