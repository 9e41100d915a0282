/* phgmg.h — structure-preserving model order reduction of port-Hamiltonian
   systems by generalized manifold Galerkin (GMG) reduction. Single header, C99.
   (manual: written at the end of the first session; see README.md) */
