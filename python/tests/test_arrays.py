"""Array handling: float64 C-contiguous read in place, others converted once, outputs float64
arrays that own the C++ results (no copy on the way out either)."""

import numpy as np

import pcl_ddg
from pcl_ddg import _pcl_ddg
from conftest import icosphere


def test_float64_c_contiguous_is_read_in_place():
    V, F = icosphere(2)
    assert V.dtype == np.float64 and V.flags.c_contiguous
    # The Python layer passes the same object on (no np.asarray copy) ...
    assert pcl_ddg._array(V, "V") is V
    # ... and every mesh function reads the library's positions from the array's own buffer.
    address = V.__array_interface__["data"][0]
    for call in (lambda v: pcl_ddg.vertex_normals(v, F), lambda v: pcl_ddg.laplacian(v, F),
                 lambda v: pcl_ddg.mass_matrix(v, F), lambda v: pcl_ddg.curvatures(v, F),
                 lambda v: pcl_ddg.mesh_report(v, F)):
        call(V)
        assert _pcl_ddg._last_positions_address() == address
        # float32, Fortran order and strided views are converted (once, in C++).
        for other in (V.astype(np.float32), np.asfortranarray(V), np.hstack([V, V])[:, ::2]):
            call(other)
            assert _pcl_ddg._last_positions_address() not in (0, address,
                                                              other.__array_interface__["data"][0])


def test_float32_non_contiguous_and_integer_input_give_the_same_results():
    V, F = icosphere(3)
    V32 = V.astype(np.float32)
    reference = pcl_ddg.curvatures(V32.astype(np.float64), F)
    wide = np.zeros((V.shape[0], 6))
    wide[:, ::2] = V32
    for variant in (V32, np.asfortranarray(V32.astype(np.float64)), wide[:, ::2], V32[::1]):
        c = pcl_ddg.curvatures(variant, F)
        np.testing.assert_array_equal(c.mean, reference.mean)
    for faces in (F.astype(np.int32), F.astype(np.int64), F.astype(np.uint32), F.tolist(),
                  np.asfortranarray(F)):
        np.testing.assert_array_equal(pcl_ddg.curvatures(V32, faces).gauss, reference.gauss)
    grid = np.arange(300, dtype=np.int64).reshape(100, 3) * np.array([1, 7, 13])
    assert pcl_ddg.estimate_normals(grid % 17).normals.dtype == np.float64


def test_outputs_are_float64_views_of_the_cpp_results():
    V, F = icosphere(2)
    n = pcl_ddg.vertex_normals(V, F).normals
    assert n.dtype == np.float64 and n.flags.c_contiguous and n.shape == V.shape
    # Owned by a capsule holding the Eigen matrix: handed over, not copied.
    assert not n.flags.owndata and type(n.base).__name__ == "PyCapsule"
    L = pcl_ddg.laplacian(V, F)
    for array in (L.data, L.indices, L.indptr):
        owner = array
        while isinstance(owner, np.ndarray):  # scipy may keep a view of ours
            owner = owner.base
        assert type(owner).__name__ == "PyCapsule"
    c = pcl_ddg.curvatures(V, F)
    assert type(c.mean.base).__name__ == "PyCapsule"
