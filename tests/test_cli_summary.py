"""The console lines of a harvest (issue 25 item 6): each berry's position and orientation
errors, a berry grasped outside tolerance flagged, and counts in the singular for one."""

from __future__ import annotations

from softarm.commands.harvest import Tolerance, line, summary
from softarm.formatting import plural
from softarm.harvest.machine.states import HarvestState
from softarm.harvest.records.report import BerryResult, HarvestReport


def _berry(tag: int, pos_mm: float, ang_deg: float) -> BerryResult:
    return BerryResult(
        tag_id=tag,
        harvested=True,
        final_state=HarvestState.DONE,
        position_error_mm=pos_mm,
        orientation_error_deg=ang_deg,
        true_position_error_mm=0.0,  # exactly on: must not fall back to the measured one
        true_orientation_error_deg=ang_deg,
        duration_s=3.0,
    )


def test_a_berry_grasped_off_axis_shows_its_angle_and_is_flagged() -> None:
    off = _berry(10, 0.3, 7.0)
    text = line(0, 1, off, 1.0)
    assert "error   0.00 mm,  7.0 deg" in text and "OUTSIDE TOLERANCE" in text
    assert "orientation > 5 deg" in text
    ok = line(0, 1, _berry(11, 0.3, 1.2), 1.0)
    assert "1.2 deg" in ok and "OUTSIDE" not in ok
    # The tolerance is the run's: 10 deg admits the 7 deg grasp.
    assert "OUTSIDE" not in line(0, 1, off, 1.0, tol=Tolerance(0.5, 10.0))


def test_summary_gives_both_means_and_counts_the_berries_outside() -> None:
    report = HarvestReport(berries=[_berry(10, 0.3, 7.0), _berry(11, 0.2, 1.0)])
    text = summary(report.to_dict())
    assert "mean fine-positioning error 0.00 mm, 4.0 deg" in text
    assert "1 berry OUTSIDE TOLERANCE" in text
    assert "OUTSIDE" not in summary(report.to_dict(), Tolerance(0.5, 8.0))


def test_one_berry_is_singular() -> None:
    assert plural(1, "berry") == "1 berry"
    assert plural(2, "berry") == "2 berries" and plural(0, "seed") == "0 seeds"


def test_the_tolerance_is_the_rigs_config() -> None:
    from softarm.harvest import HarvestConfig

    assert Tolerance.of(None) == Tolerance() == Tolerance(0.5, 5.0)
    t = Tolerance.of(HarvestConfig(fine_tolerance=0.002, angle_tolerance_deg=9.0))
    assert t == Tolerance(2.0, 9.0)


def test_a_run_that_never_moved_has_no_cane_gap() -> None:
    # A rendered bush whose map holds no ripe berry: no step ran, the gap is unknown
    # (the report's JSON has None for the watch's infinite gap).
    report = HarvestReport(berries=[])
    report.extra.update(min_branch_gap_m=None, branch_contact_steps=0, sim_time_s=0.0)
    text = summary(report.to_dict())
    assert "harvested 0/0" in text and "min cane gap -, 0 contact steps" in text
