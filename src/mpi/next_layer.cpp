#include "fictus/mpi/next_layer.hpp"

#include <algorithm>
#include <stdexcept>

#include "fictus/mpi/slab_solver.hpp"

namespace fictus::mpi {

template <int dim>
GridVector with_next_layer(const Grid<dim>& grid, const Slab& slab, const GridVector& local, const Communicator& comm) {
  const std::size_t layer = grid.layer_size();
  if (local.size() != grid.slab_size(slab)) throw std::invalid_argument("with_next_layer: vector size mismatch");
  GridVector out(local.size() + layer, 0.0);
  std::copy(local.begin(), local.end(), out.begin());
  // The ranks that hold layers are 0 … holders − 1 (default_slab fills them in order).
  int holders = 0;
  for (int r = 0; r < comm.size(); ++r)
    if (default_slab(grid.layers(), r, comm.size()).count > 0) holders = r + 1;
  const int rank = comm.rank();
  const bool holds = slab.count > 0;
  int to = MPI_PROC_NULL, from = MPI_PROC_NULL;  // send my first layer to the previous holder
  if (holds) {
    if (rank > 0)
      to = rank - 1;
    else if (grid.periodic())
      to = holders - 1;
    if (rank + 1 < holders)
      from = rank + 1;
    else if (grid.periodic())
      from = 0;
  }
  const double* first = holds ? local.data() : out.data();
  // Layers fit an int count: a 2048³ layer has 4.2 million entries.
  MPI_Sendrecv(first, holds && to != MPI_PROC_NULL ? int(layer) : 0, MPI_DOUBLE, to, 0, out.data() + local.size(),
               from != MPI_PROC_NULL ? int(layer) : 0, MPI_DOUBLE, from, 0, comm.get(), MPI_STATUS_IGNORE);
  return out;
}

template GridVector with_next_layer(const Grid<2>&, const Slab&, const GridVector&, const Communicator&);
template GridVector with_next_layer(const Grid<3>&, const Slab&, const GridVector&, const Communicator&);

}  // namespace fictus::mpi
