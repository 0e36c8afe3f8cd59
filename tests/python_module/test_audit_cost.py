"""bench/audit_cost.py --quick as a smoke test: the benchmark runs, its rows add up and the
guarantees it reads are in the reports. Nothing is timed here (speed: docs/BENCHMARKS.md)."""
import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("torch")

SCRIPT = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "bench",
                      "audit_cost.py")


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("audit_cost") / "quick.json"
    # One thread also for the tests that run beside it (the script sets torch's own).
    env = dict(os.environ, OMP_NUM_THREADS="1")
    subprocess.run([sys.executable, SCRIPT, "--quick", "--json", str(out)], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    return json.loads(out.read_text())


def test_every_audit_of_both_policies_ran_and_held(quick):
    seen = {(r["policy"], r["audit"], json.dumps(r["options"])) for r in quick["runs"]}
    assert ("trivial", "audit_policy", "{}") in seen
    assert ("trivial", "audit_policy", json.dumps({"groups": ["se3"]})) in seen
    assert ("trivial", "audit_policy", json.dumps({"groups": ["se3"], "test_law": True})) in seen
    assert ("unet", "assert_equivariant", json.dumps({"precision": "float32"})) in seen
    assert all(r["held"] is True for r in quick["runs"])


def test_the_rows_of_each_part_add_up_to_the_rows_counted(quick):
    for run in quick["runs"]:
        where = run["where"]
        # The preflight: 27 rows in 7 calls, and 6 in 2 more for a batched policy.
        assert where["preflight"] == {"rows": 33, "calls": 9}
        parts = ["preflight"] + [k for k in where if k.count(",") == 1]
        assert sum(where[k]["rows"] for k in parts) == run["rows"]
        for key in [k for k in where if k.endswith("distribution")]:
            split = where[key + ", probe"]["rows"] + where.get(key + ", draw", {"rows": 0})["rows"]
            assert split == where[key]["rows"]
        if run["audit"] == "assert_equivariant":
            assert not any("distribution" in k for k in where)


def test_the_guarantees_are_those_the_reports_state(quick):
    for run in quick["runs"]:
        if run["audit"] != "audit_policy":
            continue
        g = run["guarantees"]
        assert g["equivariant"] == g["checks"]
        # The worst pointwise "yes" is the one with the fewest far cases: 1 - 0.01^(1/n).
        n = g["pointwise_cases_min"]
        assert g["detectable_frequency"] == pytest.approx(1 - 0.01 ** (1 / n))
        # It holds pointwise, so its laws follow from that; tested, they are compared exactly
        # (affine in its noise): no test's power either way.
        tested = run["options"].get("test_law", False)
        assert g["distribution_methods"] == ["exact_gaussian" if tested else "from_pointwise"]
        assert g["detectable_shift"] is None and g["detectable_scale_ratio"] is None


def test_a_law_from_the_pointwise_yes_asks_no_row_of_its_own(quick):
    runs = {(r["audit"], json.dumps(r["options"])): r for r in quick["runs"]
            if r["policy"] == "trivial"}
    for groups in (None, ["se3"]):
        options = {"groups": groups} if groups else {}
        derived = runs[("audit_policy", json.dumps(options))]
        tested = runs[("audit_policy", json.dumps(dict(options, test_law=True)))]
        assert not any("distribution" in k for k in derived["where"])
        assert any("distribution" in k for k in tested["where"])
        assert derived["rows"] < tested["rows"]


def test_detect_asks_the_cases_its_frequency_needs_and_no_more(quick):
    runs = {(r["audit"], json.dumps(r["options"])): r for r in quick["runs"]
            if r["policy"] == "trivial"}
    for groups in (None, ["se3"]):
        options = {"groups": groups} if groups else {}
        default = runs[("audit_policy", json.dumps(options))]
        detect = runs[("audit_policy", json.dumps(dict(options, detect=0.2)))]
        # --quick's default is 20 cases, detect=0.2 asks 21: ln 0.01 / ln 0.8 = 20.6.
        assert detect["guarantees"]["detect"] == {"frequency": 0.2, "cases": 21}
        assert detect["guarantees"]["pointwise_drawn_min"] == 21
        assert default["guarantees"]["pointwise_drawn_min"] == 20
        assert detect["held"] is True
