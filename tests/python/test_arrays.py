"""Surface.vertices / Surface.triangles: zero-copy, read-only NumPy views owned by the model."""
import gc

import numpy as np
import pytest

import cadclash


def test_views_share_the_models_storage(boxes):
    model = cadclash.load(boxes)
    s = model.surfaces[0]
    v, t = s.vertices, s.triangles
    assert v.dtype == np.float64 and v.shape[1] == 3 and v.shape[0] > 0
    assert t.dtype == np.uint32 and t.shape[1] == 3 and t.shape[0] > 0
    assert t.max() < len(v)
    # Two accesses are two views of one buffer: nothing was copied.
    assert np.shares_memory(v, s.vertices) and np.shares_memory(t, s.triangles)
    assert v.base is model and t.base is model
    assert v.flags.c_contiguous and not v.flags.owndata
    # box_a is the unit cube: every coordinate of its faces is 0 or 1.
    assert set(np.unique(v)) <= {0.0, 1.0}


def test_views_are_read_only(boxes):
    model = cadclash.load(boxes)
    v, t = model.surfaces[0].vertices, model.surfaces[0].triangles
    assert not v.flags.writeable and not t.flags.writeable
    with pytest.raises(ValueError):
        v[0, 0] = 42.0
    with pytest.raises(ValueError):
        t[0, 0] = 0
    with pytest.raises(ValueError):
        v.setflags(write=True)  # a view of memory it does not own cannot be made writeable


def test_view_keeps_the_model_alive(boxes):
    model = cadclash.load(boxes)
    v = model.surfaces[3].vertices
    expected = v.copy()
    del model
    gc.collect()
    np.testing.assert_array_equal(v, expected)


def test_lazy_surface_is_tessellated_on_first_access(as1_path):
    model = cadclash.load(as1_path, lazy=True)
    s = model.surfaces[0]
    assert not s.has_triangles
    v0, t0 = s.mesh(tessellate=False)
    assert v0.shape == (0, 3) and t0.shape == (0, 3)
    v = s.vertices  # tessellates this one surface in the model, then views it
    assert s.has_triangles and v.shape[0] > 0 and len(s.triangles) > 0
    assert np.shares_memory(v, s.vertices) and v.base is model
    assert not model.surfaces[1].has_triangles  # only what was asked for
    assert model.tessellate([1, 2]) == []
    assert model.surfaces[1].has_triangles and model.surfaces[2].has_triangles


def test_lazy_and_eager_meshes_agree(as1, as1_path):
    lazy = cadclash.load(as1_path, lazy=True)
    assert lazy.tessellate() == []
    assert lazy.triangle_count == as1.triangle_count
    for a, b in zip(lazy.surfaces[:20], as1.surfaces[:20]):
        np.testing.assert_array_equal(a.triangles, b.triangles)
        np.testing.assert_array_equal(a.vertices, b.vertices)
