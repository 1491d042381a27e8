"""ehm.person: the person as one frozen value, and every entry point taking it."""

import dataclasses
import json
import pickle
import warnings

import numpy as np
import pytest

import ehm
from ehm import BodySize, InputError, Parameters, Person, SeatedHuman
from ehm.person.person import Built, as_person


class _Seen(Exception):
    """Raised by a stand-in to stop an entry point once it has built its person."""


# ---------------------------------------------------------------------------------------------- value semantics
def test_default_person_is_the_shipped_one_and_prints_short():
    p = Person.default()
    assert p == Person() and hash(p) == hash(Person())
    assert isinstance(p.params, Parameters) and p.params.origin == "default"
    assert repr(p) == "Person()"
    assert repr(Person(posture="slouched", lock="lower_neck")) == "Person(posture='slouched', lock=('lower_neck',))"
    assert p.describe().startswith("erect, back support high, reference size, head control off")
    assert "step 1 ms" in p.describe()


def test_person_is_frozen_and_replace_is_checked():
    p = Person(posture="slouched")
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.posture = "erect"
    q = p.replace(back_support="none")
    assert (p.back_support, q.back_support, q.posture) == (None, "none", "slouched")
    with pytest.raises(InputError, match="Person has no field 'stature'; change one of params, body"):
        p.replace(stature=1.8)
    with pytest.raises(InputError, match="unknown back support 'sofa'"):
        p.replace(back_support="sofa")


def test_a_path_is_read_and_equal_values_are_equal(tmp_path):
    path = tmp_path / "p.toml"
    Parameters.load().export(path)
    a, b = Person(params=path), Person(params=str(path))
    assert a == b and hash(a) == hash(b) and isinstance(a.params, Parameters)
    assert a != Person()  # another origin
    assert Person(lock=["t12", "lower_neck", "t12"]).lock == ("lower_neck", "t12")  # sorted, once each
    assert Person(lock=["t12"]) != Person(lock=["lower_neck"])
    assert len({Person(), Person(), Person(posture="slouched")}) == 2


def test_head_control_gains_are_kept_immutably():
    gains = {"tilt_stiffness_Nm_per_rad": 30.0, "delay_s": 0.03}
    p = Person(head_control=gains)
    gains["delay_s"] = 0.5  # the caller's dict changes; the person does not
    assert p.head_control == (("delay_s", 0.03), ("tilt_stiffness_Nm_per_rad", 30.0))
    assert p.head_control_gains == {"delay_s": 0.03, "tilt_stiffness_Nm_per_rad": 30.0}
    assert hash(p) == hash(Person(head_control={"delay_s": 0.03, "tilt_stiffness_Nm_per_rad": 30}))
    assert Person(head_control={}).head_control is True


@pytest.mark.parametrize("kw, words", [
    ({"params": 3}, ("Person: params must be a parameter file's path", "not 3")),
    ({"posture": "lying"}, ("unknown posture 'lying'", "erect, slouched")),
    ({"posture": 3}, ("Person: posture = 3 is not a name",)),
    ({"back_support": "sofa"}, ("unknown back support 'sofa'", "none, low, high, full")),
    ({"head_control": "yes"}, ("head_control must be True, False, None or a dict of gains",)),
    ({"head_control": {"kp": 1.0}}, ("unknown head-control gain 'kp'",)),
    ({"lock": ["elbow"]}, ("unknown joint 'elbow'",)),
    ({"lock": 3}, ("Person: lock must be a joint name",)),
    ({"lock": "t12", "unlock": "t12"}, ("both locked and unlocked",)),
    ({"dt_s": 0.5}, ("dt_s = 0.5",)),
    ({"size": {"stature_m": 1.8}}, ("size must be an ehm.person.scaling.BodySize", "not a dict")),
    ({"body": "tables"}, ("body = 'tables'", "ehm.load_body")),
])
def test_every_bad_value_is_one_sentence(kw, words):
    with pytest.raises(InputError) as exc:
        Person(**kw)
    msg = str(exc.value)
    assert "\n" not in msg and msg.endswith(".")
    for w in words:
        assert w in msg, (w, msg)


def test_to_dict_and_back_and_pickle():
    p = Person(posture="slouched", back_support="low", head_control={"delay_s": 0.03}, lock=["lower_neck"],
               unlock=["waist"], dt_s=0.0005, size=BodySize(1.9, 90.0))
    d = p.to_dict()
    assert json.loads(json.dumps(d)) == d  # plain JSON data
    assert d["head_control"] == {"delay_s": 0.03} and d["size"]["stature_m"] == 1.9 and d["params"] == "default"
    assert Person.from_dict(d) == p
    assert pickle.loads(pickle.dumps(p)) == p
    with pytest.raises(InputError, match="unknown key 'stature'"):
        Person.from_dict({"stature": 1.8})
    custom = Person(body=ehm.load_body())
    with pytest.raises(InputError, match="custom body tables"):
        Person.from_dict(custom.to_dict())
    assert Person.from_dict(custom.to_dict(), body=ehm.load_body()) == custom


def test_resolved_is_what_the_constructor_did():
    p = Person(posture="slouched", back_support="none", head_control=True, lock="lower_neck", size=BodySize(1.9, 90))
    built = p.resolved()
    assert isinstance(built, Built)
    assert built.params.posture == "slouched" and built.params.back_support == "none"
    assert built.params.value("head_control.enabled") is True
    assert built.params.value("simulation.dt_s") == 0.001  # the slouched posture converges at the shipped step
    assert {"lower_neck", "waist"} <= built.locked
    assert built.body.mass_kg == pytest.approx(90.0)
    with pytest.warns(ehm.StepWarning):
        Person(dt_s=0.002).resolved()


def test_as_person_builds_or_changes():
    p = Person(posture="slouched")
    assert as_person(p) is p
    assert as_person(p, lock=()) is p  # an empty shortcut changes nothing
    assert as_person(p, dt_s=0.0005) == p.replace(dt_s=0.0005)
    assert as_person(None, posture="slouched") == p
    with pytest.raises(InputError, match="params must be a parameter file's path, an ehm.Parameters, an ehm.Person"):
        as_person(3.0)


# ---------------------------------------------------------------------------------------------- entry points
def test_person_and_keywords_build_the_same_human_bit_for_bit():
    kw = dict(posture="slouched", back_support="low", lock=["lower_neck"], head_control=True)
    by_person, by_keywords = SeatedHuman(Person(**kw)), SeatedHuman(**kw)
    assert by_keywords.person == by_person.person == Person(**kw)
    assert SeatedHuman(person=Person(**kw)).person == Person(**kw)
    motion = ehm.random_vibration("z", duration_s=1.0, rms_mps2=0.3, seed=0)
    a = by_person.simulate(motion, method="nonlinear")
    b = by_keywords.simulate(motion, method="nonlinear")
    np.testing.assert_array_equal(a.point("head").acc_mps2, b.point("head").acc_mps2)
    np.testing.assert_array_equal(a.support_N["seat_pan"], b.support_N["seat_pan"])
    # the recipe carries the person to a worker
    again = SeatedHuman.from_recipe(pickle.loads(pickle.dumps(by_person.recipe())))
    assert again.person == by_person.person
    with pytest.raises(InputError, match="either first or as person="):
        SeatedHuman(Person(), person=Person())


def test_keywords_given_with_a_person_change_it():
    human = SeatedHuman(Person(posture="slouched"), back_support="none")
    assert human.person == Person(posture="slouched", back_support="none")
    assert human.params.back_support == "none"


def test_simulator_honours_posture_head_control_and_step():
    sim = ehm.Simulator(Person(posture="slouched", head_control=True, dt_s=0.0005))
    assert sim.person.posture == "slouched"
    assert sim.human.params.posture == "slouched" and sim.human.head_control
    assert sim.dt_s == 0.0005


def test_frf_takes_a_person():
    p = Person(lock="lower_neck")
    a = ehm.linear_frf(p, "z")
    b = ehm.linear_frf(SeatedHuman(p), "z")
    np.testing.assert_array_equal(a.curve("z", "head", "z").gain, b.curve("z", "head", "z").gain)
    with pytest.raises(InputError, match="give an ehm.Person or an ehm.SeatedHuman"):
        ehm.linear_frf("person")


def test_assess_takes_a_person():
    motion = ehm.random_vibration("z", duration_s=3.0, rms_mps2=0.3, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ehm.EhmWarning)  # a short drive's band note
        a = ehm.assess(motion, Person(lock="lower_neck"), method="linear")
        b = ehm.assess(motion, SeatedHuman(lock="lower_neck"), method="linear")
    assert a.summary()["locations"] == b.summary()["locations"]
    with pytest.raises(InputError, match="give an ehm.Person, an ehm.SeatedHuman or None"):
        ehm.assess(motion, "someone")


def _capture(monkeypatch, module):
    """Stand in for ``module.linear_frf``: keep the human it was given, then stop."""
    seen = []

    def fake(human, *args, **kwargs):
        seen.append(human)
        raise _Seen

    monkeypatch.setattr(module, "linear_frf", fake)
    return seen


def test_check_step_honours_posture_and_head_control(monkeypatch):
    import ehm.analysis.convergence

    seen = _capture(monkeypatch, ehm.analysis.convergence)
    with pytest.raises(_Seen):
        ehm.check_step(Person(posture="slouched", head_control=True))
    human = seen[0]
    assert human.params.posture == "slouched" and human.head_control
    assert human.params.value("simulation.dt_s") == pytest.approx(0.001 / 8)  # the person's own step, / 8


def test_validate_honours_locks_and_head_control(monkeypatch):
    import ehm.analysis.validation

    seen = _capture(monkeypatch, ehm.analysis.validation)
    with pytest.raises(_Seen):
        ehm.validate(Person(head_control=True, lock="lower_neck"))
    assert seen[0].head_control and "lower_neck" in seen[0].locked


def test_cli_validate_head_control_applies(monkeypatch):
    import ehm.analysis.validation
    from ehm.interfaces.cli.common import person_from_args
    from ehm.interfaces.cli.parser import build_parser

    args = build_parser().parse_args(["validate", "--head-control", "--posture", "slouched", "--dt", "0.0005"])
    assert person_from_args(args) == Person(head_control=True, posture="slouched", dt_s=0.0005)
    seen = _capture(monkeypatch, ehm.analysis.validation)
    with pytest.raises(_Seen):
        args.func(args)
    assert seen[0].head_control and seen[0].params.posture == "slouched"


def test_cli_builds_one_person_for_every_command():
    from ehm.interfaces.cli.common import person_from_args
    from ehm.interfaces.cli.parser import build_parser

    parser = build_parser()
    args = parser.parse_args(["check-step", "--lock", "lower_neck,t12", "--head-control-gains", "delay_s=0.03",
                              "--stature", "1.9", "--mass", "90", "--dt", "0.0005"])
    p = person_from_args(args)
    assert p.lock == ("lower_neck", "t12") and p.head_control == (("delay_s", 0.03),) and p.dt_s == 0.0005
    assert p.size.stature_m == 1.9
    with pytest.raises(InputError, match="--dt"):
        person_from_args(parser.parse_args(["check-step", "--dt", "1"]))
    assert person_from_args(parser.parse_args(["info"])) == Person()  # a command without --dt: the person's own


def test_cli_check_step_posture_and_head_control_apply(monkeypatch):
    import ehm.analysis.convergence
    from ehm.interfaces.cli.parser import build_parser

    args = build_parser().parse_args(["check-step", "--posture", "slouched", "--head-control"])
    seen = _capture(monkeypatch, ehm.analysis.convergence)
    with pytest.raises(_Seen):
        args.func(args)
    assert seen[0].params.posture == "slouched" and seen[0].head_control


def test_export_fmu_takes_a_person(tmp_path):
    from ehm.interfaces.fmu import export_fmu

    with pytest.raises(InputError, match="pythonfmu unit"):
        export_fmu(tmp_path / "p.fmu", Person(dt_s=0.0005), python=True)


def test_batch_runs_build_persons():
    from ehm.interfaces.batch import RunSpec

    spec = RunSpec("r", {"stature_m": 1.9, "mass_kg": 90.0}, {"seat.back_support": "low"}, ("lower_neck",),
                   ("transmissibility",), {})
    p = spec.build_person()
    assert isinstance(p, Person) and p.lock == ("lower_neck",) and p.size.mass_kg == 90.0
    assert p.params.back_support == "low"


def test_locking_study_adds_its_locks_to_the_persons(monkeypatch):
    import ehm.analysis.study

    seen = _capture(monkeypatch, ehm.analysis.study)
    with pytest.raises(_Seen):
        ehm.analysis.study.locking_study(Person(lock="lower_neck"), variants={"SL": ("t12",)})
    assert "lower_neck" in seen[0].locked  # the baseline is the person as given
