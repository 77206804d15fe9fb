"""Reading and reducing a model's equations: constraints eliminated through the penalty
terms' null space, massless DOFs condensed statically."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_opensees.matrices import Equations, ReductionError, constraint_basis, reduce


def _equations(mass, stiffness, constraint, damping=None):
    n = len(mass)
    labels = {(node, 1): node - 1 for node in range(1, n + 1)}
    damping = np.zeros((n, n)) if damping is None else damping
    return Equations(np.diag(mass), damping, np.asarray(stiffness, float), constraint, labels)


def test_a_chain_of_ties_leaves_one_coordinate_kept_where_preferred():
    # u1 = u2 and u2 = u3 (a chain), u4 fixed, u5 free: penalty terms of unit penalty
    constraint = np.zeros((5, 5))
    for a, b in ((0, 1), (1, 2)):
        constraint[np.ix_([a, b], [a, b])] += [[1.0, -1.0], [-1.0, 1.0]]
    constraint[3, 3] = 1.0
    weight = np.array([1.0, 1.0, 4.0, 1.0, 1.0])
    basis, independent = constraint_basis(constraint, weight)
    assert independent.tolist() == [2, 4]
    np.testing.assert_allclose(basis, [[1, 0], [1, 0], [1, 0], [0, 0], [0, 1]], atol=1e-12)


def test_massless_dofs_follow_the_others_statically():
    """Two masses on springs 1 -- 2 -- (massless 3) -- ground: the massless node is
    condensed into the series stiffness, exactly."""
    k1, k2, k3 = 3.0e6, 2.0e6, 1.0e6
    stiffness = np.array([[k1, -k1, 0.0], [-k1, k1 + k2, -k2], [0.0, -k2, k2 + k3]])
    damping = 0.01 * stiffness
    equations = _equations([2.0e3, 1.0e3, 0.0], stiffness, np.zeros((3, 3)), damping)
    reduced = reduce(equations)
    assert reduced.dofs == ((1, 1), (2, 1))
    series = k2 * k3 / (k2 + k3)
    np.testing.assert_allclose(reduced.stiffness, [[k1, -k1], [-k1, k1 + series]])
    np.testing.assert_allclose(reduced.damping, 0.01 * reduced.stiffness)
    np.testing.assert_allclose(reduced.shapes[2], [0.0, k2 / (k2 + k3)])
    np.testing.assert_allclose(reduced.mass, np.diag([2.0e3, 1.0e3]))


def test_a_massless_mechanism_is_refused():
    """Two massless DOFs joined to each other by a spring and to nothing else."""
    k = 1.0e6
    stiffness = np.array([[k, 0.0, 0.0], [0.0, k, -k], [0.0, -k, k]])
    with pytest.raises(ReductionError, match=r"singular stiffness \(a mechanism\)"):
        reduce(_equations([1.0e3, 0.0, 0.0], stiffness, np.zeros((3, 3))))


def test_a_massless_dof_held_by_a_very_soft_spring_is_condensed_not_refused():
    """A mass on a spring k1 to a massless node held to the ground by 1e8, and a massless
    hinge hanging on that node by 1e-9 alone (a leaning column's rotational springs, as
    published in kip in/rad): the massless equations span 17 orders of magnitude but are
    not a mechanism. By hand: the hinge follows its node, which takes k1 / (k1 + 1e8) of
    the mass's displacement, and the mass sees the series stiffness."""
    k1, ground, soft = 1.0e6, 1.0e8, 1.0e-9
    stiffness = np.array([[k1, -k1, 0.0], [-k1, k1 + ground + soft, -soft], [0.0, -soft, soft]])
    reduced = reduce(_equations([1.0e3, 0.0, 0.0], stiffness, np.zeros((3, 3))))
    assert reduced.dofs == ((1, 1),)
    np.testing.assert_allclose(reduced.stiffness, [[k1 * ground / (k1 + ground)]], rtol=1e-9)
    share = k1 / (k1 + ground)
    np.testing.assert_allclose(reduced.shapes[:, 0], [1.0, share, share], rtol=1e-9)
