"""`farlio bench`: farlio's stage breakdown nests in the whole frame, several --threads values give
one bench.json entry each, the work and memory fields are filled, and --help documents every
option. Few generated scans and --no-kiss: these check what the benchmark reports, never how fast
anything is (timings belong in benchmarks)."""

from __future__ import annotations

import argparse
import io
import json
from contextlib import redirect_stdout

import numpy as np
import pytest

pytest.importorskip("farlio._core")

from farlio import _core  # noqa: E402
from farlio.benchmark import OTHER, STAGES, WORK_COUNTS, generated_scans, run_farlio  # noqa: E402
from farlio.cli import build_parser, main  # noqa: E402

PROFILE = "handheld"  # the smaller generated scans: a fast test
SCANS = 5
THREADS = (1, 2)
BENCH = ["bench", "--profile", PROFILE, "--scans", str(SCANS), "--no-kiss", "--device", "cpu"]
#: the stages run inside the timed frame: per frame their sum stays within it, up to clock jitter
FRAME_FACTOR = 1.05
FRAME_SLACK_MS = 0.2
MEMORY_FIELDS = ("map_bytes", "map_voxels", "map_points", "peak_rss_mib")


@pytest.fixture(scope="module")
def two_thread_counts(tmp_path_factory) -> tuple[dict, str]:
    """bench.json and the printed text of one bench with two --threads values."""
    out, text = tmp_path_factory.mktemp("bench"), io.StringIO()
    with redirect_stdout(text):
        assert main(BENCH + ["--threads", *map(str, THREADS), "--out", str(out)]) == 0
    return json.loads((out / "bench.json").read_text()), text.getvalue()


def test_stages_sum_to_at_most_the_whole_frame():
    scans, _, _ = generated_scans(PROFILE, SCANS)
    config = _core.Config()
    config.set("device", "cpu")
    run = run_farlio(scans, config)
    frame_ms = np.asarray(run.frame_ms)
    sums = run.stage_sums_ms()
    assert sums.shape == frame_ms.shape == (SCANS,)
    assert np.all(sums > 0), sums
    assert np.all(sums <= frame_ms * FRAME_FACTOR + FRAME_SLACK_MS), (sums, frame_ms)


def test_two_thread_counts_give_one_entry_each(two_thread_counts):
    results, _ = two_thread_counts
    assert set(results) == {f"{PROFILE} threads={t}" for t in THREADS}
    for t in THREADS:
        assert results[f"{PROFILE} threads={t}"]["threads"] == t


def test_stage_medians_are_positive_and_within_their_p99(two_thread_counts):
    results, _ = two_thread_counts
    for r in results.values():
        stages = r["farlio"]["stages_ms"]
        assert set(stages) == {*STAGES, OTHER}
        for stage in STAGES:
            assert 0 < stages[stage]["median"] <= stages[stage]["p99"], (stage, stages[stage])
        latency = r["farlio"]["latency_ms"]
        assert sum(stages[s]["median"] for s in STAGES) <= latency["median"] * FRAME_FACTOR + FRAME_SLACK_MS
        assert r["farlio"]["p99_over_median"] == pytest.approx(latency["p99"] / latency["median"])


def test_work_and_memory_are_reported(two_thread_counts):
    results, text = two_thread_counts
    for r in results.values():
        work, memory = r["farlio"]["work"], r["farlio"]["memory"]
        assert set(work) == set(WORK_COUNTS)
        assert work["iterations"] > 0
        assert 0 < work["source_points"] <= work["kept_points"] < r["points_per_scan"]
        for name in MEMORY_FIELDS:
            assert memory[name] > 0, (name, memory)
    for heading in ("stage", "preprocess", "map update", "whole frame", "p99/median", "work (median", "memory: map"):
        assert text.count(heading) >= len(THREADS), heading


def test_each_stage_has_its_limit_and_ratio(two_thread_counts):
    results, text = two_thread_counts
    for r in results.values():
        sticks = r["yardsticks"]
        assert sticks["memory_read_gb_s"] > 0 and sticks["l1_distances_g_s"] > 0, sticks
        limits, stages = r["farlio"]["stage_limits"], r["farlio"]["stages_ms"]
        assert set(limits) == {*STAGES, "whole_frame"}
        for stage in STAGES:
            assert limits[stage]["limit_ms"] > 0, (stage, limits[stage])
            assert limits[stage]["ratio"] == pytest.approx(stages[stage]["median"] / limits[stage]["limit_ms"])
        # the whole frame's limit is the median of the frames' sums: at least each stage's median limit
        whole = limits["whole_frame"]
        assert max(limits[s]["limit_ms"] for s in STAGES) <= whole["limit_ms"]
        assert whole["ratio"] == pytest.approx(r["farlio"]["latency_ms"]["median"] / whole["limit_ms"])
    assert text.count("/ limit") >= len(THREADS) and text.count("G distances/s") >= len(THREADS)


def test_one_thread_count_keeps_the_plain_key(tmp_path):
    assert main(BENCH + ["--out", str(tmp_path)]) == 0
    results = json.loads((tmp_path / "bench.json").read_text())
    assert list(results) == [PROFILE]
    assert results[PROFILE]["threads"] == 0


def test_help_documents_every_option():
    parser = build_parser()
    bench = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices["bench"]
    for action in bench._actions:
        assert action.help and action.help != argparse.SUPPRESS, action.option_strings


def test_passes_with_new_pipelines_give_the_same_poses():
    """What FarlioRun.pool relies on to keep one pass's trajectory: a new pipeline over the same
    scans gives the same poses, bit for bit."""
    scans, _, _ = generated_scans(PROFILE, SCANS)
    config = _core.Config()
    config.set("num_threads", "2")
    config.set("device", "cpu")
    first, second = run_farlio(scans, config), run_farlio(scans, config)
    assert len(first.trajectory) == len(second.trajectory) == SCANS
    for k in range(SCANS):
        (s1, p1), (s2, p2) = first.trajectory[k], second.trajectory[k]
        assert s1 == s2
        assert np.array_equal(np.asarray(p1.matrix()), np.asarray(p2.matrix())), k


def test_rounds_pool_the_frames_of_passes_that_give_the_same_poses(tmp_path):
    """--rounds N: N passes, each with a new pipeline; the accuracy and work are those of one pass
    (the passes give the same poses: the test above), the frame times of all are pooled."""
    one, two = tmp_path / "one", tmp_path / "two"
    text = io.StringIO()
    with redirect_stdout(text):
        assert main(BENCH + ["--threads", "2", "--out", str(one)]) == 0
        assert main(BENCH + ["--threads", "2", "--rounds", "2", "--out", str(two)]) == 0
    r1 = json.loads((one / "bench.json").read_text())[PROFILE]
    r2 = json.loads((two / "bench.json").read_text())[PROFILE]
    assert (r1["rounds"], r2["rounds"]) == (1, 2)
    assert r2["frames"] == r1["frames"] == SCANS
    assert r2["farlio"]["accuracy"] == r1["farlio"]["accuracy"]
    assert r1["farlio"]["accuracy"]["ape_m"] > 0
    assert r2["farlio"]["work"] == r1["farlio"]["work"]
    assert "2 rounds in turns with KISS-ICP" in text.getvalue()


def test_rounds_give_each_pass_its_ratio_next_to_kiss_icp():
    pytest.importorskip("kiss_icp")
    from farlio.benchmark import compare

    scans, gt, _ = generated_scans(PROFILE, 3)
    r = compare(scans, gt, threads=1, device="cpu", rounds=2)
    assert r["rounds"] == 2
    per_round = r["speedup_median_per_round"]
    assert len(per_round) == 2 and all(x > 0 for x in per_round), per_round
    assert r["kiss_icp"]["accuracy"]["ape_m"] >= 0
    assert r["speedup_median"] == pytest.approx(
        r["kiss_icp"]["latency_ms"]["median"] / r["farlio"]["latency_ms"]["median"]
    )


def test_a_recording_with_ground_truth_is_evaluated_as_farlio_run_evaluates_it(tmp_path):
    # bench registers the LiDAR frame, farlio run writes the body frame: with the recording's
    # ground truth moved into the LiDAR frame, the same LiDAR-only poses give the same APE
    from farlio.config import load_config
    from farlio.datasets import open_dataset
    from farlio.runner import replay_options, run_dataset
    from farlio.simulation import generate

    seq = tmp_path / "urban"
    generate("urban", seq, duration_s=4.0, seed=2)
    out = tmp_path / "bench"
    assert main(["bench", "--data", str(seq), "--scans", "40", "--no-kiss", "--device", "cpu", "--out", str(out)]) == 0
    bench = json.loads((out / "bench.json").read_text())[str(seq)]["farlio"]["accuracy"]
    assert bench is not None
    run = run_dataset(
        open_dataset(seq),
        tmp_path / "run",
        load_config(None, ["fusion.enabled=false", "device=cpu"]),
        progress=False,
        plot=False,
        options=replay_options("zero"),
    )
    ape_run = run["accuracy"]["ape"]["translation_m"]["rmse"]
    assert bench["ape_m"] < 0.05
    assert abs(bench["ape_m"] - ape_run) < 2e-3, (bench["ape_m"], ape_run)
