"""DEAP permutation operators of Le et al. 2018's GA: invariants over many seeds, a private generator."""

import random

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.operators.permutation import Tour, TourFitness, order_crossover, select_tournament, swap_mutation


@st.composite
def permutations(draw, min_size=0, max_size=12):
    n = draw(st.integers(min_size, max_size))
    return draw(st.permutations(list(range(n))))


@settings(max_examples=150, deadline=None)
@given(permutations(), st.integers(0, 2**32 - 1))
def test_swap_mutation_swaps_two_genes(genes, seed):
    child = list(genes)
    assert swap_mutation(child, random.Random(seed)) == (child,)
    assert sorted(child) == sorted(genes)
    changed = [i for i, (a, b) in enumerate(zip(genes, child)) if a != b]
    assert len(changed) == (2 if len(genes) >= 2 else 0)
    if len(genes) >= 2:
        i, j = changed
        assert child[i] == genes[j] and child[j] == genes[i]


def _is_linear_ox_child(child, keep, fill):
    """Whether some slice [a, b) of ``keep`` sits in place in ``child`` and the rest of ``child`` is
    ``fill``'s other genes, left to right."""
    n = len(child)
    for a in range(n + 1):
        for b in range(a, n + 1):
            if child[a:b] != keep[a:b]:
                continue
            kept = set(keep[a:b])
            if child[:a] + child[b:] == [g for g in fill if g not in kept]:
                return True
    return n == 0


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 10).flatmap(lambda n: st.tuples(st.permutations(list(range(n))),
                                                      st.permutations(list(range(n))))),
       st.integers(0, 2**32 - 1))
def test_order_crossover_makes_permutations_from_a_slice_and_the_other_order(parents, seed):
    p1, p2 = list(parents[0]), list(parents[1])
    c1, c2 = Tour(p1), Tour(p2)
    assert order_crossover(c1, c2, random.Random(seed)) == (c1, c2)
    assert sorted(c1) == sorted(c2) == sorted(p1)
    assert _is_linear_ox_child(list(c1), p1, p2) and _is_linear_ox_child(list(c2), p2, p1)
    assert isinstance(c1, Tour) and isinstance(c1.fitness, TourFitness)


def test_order_crossover_keeps_the_drawn_slice_of_each_parent():
    # random.Random(5) draws the slice [2, 4), as the docstring shows
    c1, c2 = order_crossover([0, 1, 2, 3, 4, 5], [5, 4, 3, 2, 1, 0], random.Random(5))
    assert c1[2:4] == [2, 3] and c2[2:4] == [3, 2]
    assert c1 == [5, 4, 2, 3, 1, 0] and c2 == [0, 1, 3, 2, 4, 5]


def test_tournament_picks_the_cheapest_of_each_draw():
    pop = [Tour([i]) for i in range(5)]
    for t, c in zip(pop, [5.0, 4.0, 3.0, 2.0, 1.0]):
        t.fitness.values = (c,)
    # 200 draws per tournament: the cheapest (tour 4) is drawn in every one, almost surely
    assert [t[0] for t in select_tournament(pop, 20, random.Random(0), 200)] == [4] * 20
    # tournaments of one are uniform draws: every tour is picked
    assert {t[0] for t in select_tournament(pop, 200, random.Random(0), 1)} == set(range(5))


def test_tour_copy_copies_genes_and_fitness_independently():
    t = Tour([2, 0, 1])
    t.fitness.values = (3.5,)
    twin = t.copy()
    twin[0] = 9
    del twin.fitness.values
    assert t == [2, 0, 1] and t.fitness.values == (3.5,)
    assert not Tour([1]).copy().fitness.valid


def test_operators_leave_the_global_random_states_alone():
    random.seed(1)
    np.random.seed(2)
    py_state, np_state = random.getstate(), np.random.get_state()[1].copy()
    rng = random.Random(3)
    a, b = Tour(range(8)), Tour(range(7, -1, -1))
    for _ in range(20):
        order_crossover(a, b, rng)
        swap_mutation(a, rng)
    for t in (a, b):
        t.fitness.values = (float(t[0]),)
    select_tournament([a, b], 5, rng, 2)
    assert random.getstate() == py_state
    assert np.array_equal(np.random.get_state()[1], np_state)
