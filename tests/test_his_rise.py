"""His pelvis's rise handed on for a jump's push only (motion/his_rise.py): a rise begun on both feet, while on them."""

import numpy as np

from stylesync.motion.his_rise import HisRise


def _hand_on(vz_mps, on_both_feet) -> np.ndarray:
    rise = HisRise()
    return np.array([rise.rise_mps(v, b) for v, b in zip(vz_mps, on_both_feet, strict=True)])


def test_a_jumps_push_is_handed_on_while_he_stands_on_both_feet():
    # Crouch (down), push (up, both feet), take-off (up, his FSM out of double stance), fall and land (down).
    vz = [-0.3, -0.5, -0.1, 0.4, 1.2, 2.0, 1.5, 0.5, -1.0, -2.0, -0.2]
    both = [True, True, True, True, True, True, False, False, False, True, True]
    handed = _hand_on(vz, both)
    np.testing.assert_array_equal(handed[:6], vz[:6])  # the crouch as it is, then the push
    np.testing.assert_array_equal(handed[6:8], [0.0, 0.0])  # in the air the rise is not his push
    np.testing.assert_array_equal(handed[8:], vz[8:])  # a descent is handed on as it is


def test_a_strides_rise_through_a_double_stance_of_his_flight_is_not_handed_on():
    # A run's stride: the rise begins on one foot (mid-stance) and goes through a sample or two of double stance in
    # the flight, where the rising foot passes the falling one.
    vz = [-0.4, -0.1, 0.3, 0.6, 0.7, 0.6, 0.2, -0.3]
    both = [False, False, False, False, True, True, False, False]
    handed = _hand_on(vz, both)
    np.testing.assert_array_equal(handed[2:7], np.zeros(5))
    assert handed[7] == vz[7] and handed[0] == vz[0]


def test_a_rise_that_goes_on_onto_one_foot_stops_being_handed_on_and_a_new_one_needs_both_feet():
    # A rise begun on both feet; he lifts a foot (a kick's wind-up): 0 while he is on one foot; back on both feet
    # within the same rise, the push is his again.
    vz = [0.2, 0.3, 0.3, 0.3, -0.1, 0.2, 0.3]
    both = [True, True, False, True, False, False, True]
    handed = _hand_on(vz, both)
    np.testing.assert_array_equal(handed[:2], [0.2, 0.3])
    assert handed[2] == 0.0 and handed[3] == 0.3
    # a new rise begun on one foot stays out, even once he is on both feet again
    np.testing.assert_array_equal(handed[5:], [0.0, 0.0])
