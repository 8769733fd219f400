"""Stores are contiguous arrays; components read and write them in place."""

from __future__ import annotations

import pickle

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.components import Motor, Transform
from ecs_tentacles.store import MotorStore, TransformStore


def test_rows_get_defaults_then_values() -> None:
    store = TransformStore(capacity=2)
    rows = store.add(3, pos=[1.0, 2.0, 3.0])
    assert_array_equal(rows, [0, 1, 2])
    assert_array_equal(store.pos, [[1, 2, 3]] * 3)
    assert_array_equal(store.quat, [[1, 0, 0, 0]] * 3)
    assert store.pos.flags["C_CONTIGUOUS"]


def test_component_fields_are_views_into_the_store() -> None:
    store = TransformStore()
    store.add(2)
    transform = Transform(store, 1)
    transform.pos[2] += 0.5
    transform.quat = [0.0, 1.0, 0.0, 0.0]
    assert_array_equal(store.pos[1], [0, 0, 0.5])
    assert_array_equal(store.quat[1], [0, 1, 0, 0])
    store.pos[1, 0] = 7.0
    assert transform.pos[0] == 7.0


def test_scalar_fields_read_as_floats_and_write_through() -> None:
    store = MotorStore()
    store.add(2, strength=[3.0, 4.0])
    motor = Motor(store, 1)
    assert isinstance(motor.strength, float) and motor.strength == 4.0
    motor.strength = 8.0
    assert_array_equal(store.strength, [3.0, 8.0])


def test_growth_keeps_rows_and_components_follow() -> None:
    store = TransformStore(capacity=1)
    store.add(1, pos=[1.0, 1.0, 1.0])
    transform = Transform(store, 0)
    store.add(100)
    assert store.capacity >= 101 and len(store) == 101
    transform.pos[0] = 5.0
    assert store.pos[0, 0] == 5.0
    assert_array_equal(store.pos[1:], np.zeros((100, 3)))


def test_whole_array_math_on_live_rows() -> None:
    store = MotorStore(capacity=64)
    store.add(3, strength=2.0)
    store.strength *= 1.5
    assert_array_equal(store.strength, [3.0, 3.0, 3.0])
    assert len(store.strength) == 3


def test_fit_frees_the_spare_room_and_keeps_rows_and_components() -> None:
    store = TransformStore(capacity=1)
    store.add(100, pos=[1.0, 2.0, 3.0])
    transform = Transform(store, 99)
    assert store.capacity == 128
    store.fit()
    assert store.capacity == len(store) == 100
    assert_array_equal(store.pos, [[1, 2, 3]] * 100)
    transform.pos[0] = 5.0
    assert store.pos[99, 0] == 5.0
    assert_array_equal(store.add(1), [100])  # grows again
    assert len(store) == 101 and store.pos[99, 0] == 5.0


def test_field_views_follow_removal_restore_and_assignment() -> None:
    store = TransformStore(capacity=2)
    store.add(4, pos=[[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]])
    saved = store.copy_rows()
    store.remove(np.array([1]))
    assert_array_equal(store.pos[:, 0], [0, 2, 3])
    store.put_rows(saved)
    assert_array_equal(store.pos[:, 0], [0, 1, 2, 3])
    store.pos = [9.0, 9.0, 9.0]  # into the live rows, the field stays a view of them
    assert_array_equal(store._arrays["pos"][:4], [[9, 9, 9]] * 4)
    store.pos[0, 0] = 1.0
    assert store._arrays["pos"][0, 0] == 1.0


def test_a_copied_store_reads_and_writes_its_own_arrays() -> None:
    store = TransformStore()
    store.add(2, pos=[1.0, 2.0, 3.0])
    twin = pickle.loads(pickle.dumps(store))
    twin.pos[0, 0] = 7.0
    assert twin._arrays["pos"][0, 0] == 7.0 and store.pos[0, 0] == 1.0
    twin.add(1)
    assert len(twin.pos) == 3 and len(store.pos) == 2


def test_without_kept_views_every_read_goes_through_the_column_table() -> None:
    store = TransformStore()
    store.add(2)
    store.cache_views = False
    read: list[str] = []

    class Watched(dict):  # type: ignore[type-arg]
        def __getitem__(self, name: str) -> np.ndarray:
            read.append(name)
            return super().__getitem__(name)

    store._arrays = Watched(store._arrays)
    store.pos[1, 2] = 4.0
    assert read == ["pos"] and store._arrays["pos"][1, 2] == 4.0
    store.cache_views = True
    assert "pos" in vars(store)  # kept again
