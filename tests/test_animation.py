"""Animation of a run from its poses.npz: frames show the body moving, files are written whole."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import ehm
from ehm.errors import InputError
from ehm.interfaces.cli import main
from ehm.outputs.animation import _ellipse_params, animate, render_frames


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A 2 Hz fore-aft sine run and a run without input, each written to a folder with poses.npz."""
    human = ehm.SeatedHuman()
    out = {}
    for name, motion in (("sine", ehm.sine("x", 2.0, 2.0, 1.0)), ("still", ehm.random_vibration("z", 1.0, 0.0))):
        folder = tmp_path_factory.mktemp(name)
        human.simulate(motion, pose_rate_hz=25.0, method="nonlinear").write(folder)
        out[name] = folder
    return out


def _changed_pixels(a: np.ndarray, b: np.ndarray) -> int:
    """Pixels that differ clearly (RGB differences summing to over 100 of 765: more than edge smoothing), above
    the bottom strip where the time stamp is."""
    rows = int(a.shape[0] * 0.9)
    return int((np.abs(a[:rows].astype(int) - b[:rows].astype(int)).sum(axis=-1) > 100).sum())


def _changed_body_pixels(a: np.ndarray, b: np.ndarray) -> int:
    """Clearly changed pixels that show the body in either frame (segments are coloured; seat, text grey)."""
    body = [(f.max(axis=-1).astype(int) - f.min(axis=-1)) > 40 for f in (a, b)]
    rows = int(a.shape[0] * 0.9)  # not the bottom strip with the (red) exaggeration note
    changed = np.abs(a.astype(int) - b.astype(int)).sum(axis=-1) > 100
    return int((changed & (body[0] | body[1]))[:rows].sum())


def test_frames_show_the_body_moving(runs):
    frames = render_frames(runs["sine"], times_s=[0.0, 0.76, 1.0, 1.24], exaggerate=20)
    assert len(frames) == 4
    assert all(f.shape == (480, 960, 3) and f.dtype == np.uint8 for f in frames)
    # Thresholds: an order of magnitude under what this run gives (measured: 9246-16987 changed pixels,
    # 6864-13434 of them on the body) and far above the still run's (measured 0).
    moved = [_changed_pixels(frames[0], f) for f in frames[1:]]
    assert min(moved) > 1000, moved
    in_body = [_changed_body_pixels(frames[0], f) for f in frames[1:]]
    assert min(in_body) > 3000, in_body
    still = render_frames(runs["still"], times_s=[0.0, 0.48, 0.96], exaggerate=20)
    assert max(_changed_pixels(still[0], f) for f in still[1:]) < 20
    assert max(_changed_body_pixels(still[0], f) for f in still[1:]) < 20
    # The time stamp does change.
    assert np.any(still[0] != still[-1])


def test_exaggeration_scales_the_motion(runs):
    times = [0.0, 0.52]
    frozen = render_frames(runs["sine"], times_s=times, exaggerate=0)
    true_scale = render_frames(runs["sine"], times_s=times, exaggerate=1)
    big = render_frames(runs["sine"], times_s=times, exaggerate=20)
    assert _changed_pixels(*frozen) == 0
    # measured: 0 changed pixels at true scale (sub-pixel motion), 2314 at 20 times
    assert _changed_pixels(*big) > 2 * _changed_pixels(*true_scale) + 1000


def test_rotating_seat_views_follow_the_heading():
    human = ehm.SeatedHuman(rotating_seat=True)
    t = np.arange(0.0, 1.0001, 0.01)

    def frames(rates):
        w = np.tile(np.asarray(rates, dtype=float), (t.size, 1))
        run = human.simulate(ehm.SeatMotion(t, np.zeros((t.size, 3)), "turning seat", angvel_radps=w),
                             pose_rate_hz=25.0, method="nonlinear")
        assert run.poses["pos"].shape[1] == len(run.poses["geometry_segments"]) + 1  # the seat frame, last
        return render_frames(run.poses, times_s=[0.0, 1.0], exaggerate=0)  # body frozen on the seat

    assert _changed_pixels(*frames([0.0, 0.0, 0.5])) == 0  # a yawing seat: the views turn with it
    assert _changed_pixels(*frames([0.0, 0.2, 0.0])) > 5000  # a pitching seat tilts seat and person


def test_projected_ellipse_is_exact():
    rng = np.random.default_rng(1)
    a = np.array([0.23, 0.075, 0.05])
    R = Rotation.random(random_state=rng).as_matrix()
    M = R @ np.diag(a ** 2) @ R.T
    # Sample the surface; its projection onto the x-z plane must fill the ellipse of M's x-z block.
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 400), np.linspace(0, np.pi, 200))
    pts = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1).reshape(-1, 3) * a @ R.T
    width, height, angle = _ellipse_params(M[np.ix_([0, 2], [0, 2])])
    t = np.radians(angle)
    major, minor = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
    proj = pts[:, [0, 2]]
    assert np.max(proj @ major) == pytest.approx(width / 2, rel=1e-3)
    assert np.max(proj @ minor) == pytest.approx(height / 2, rel=1e-3)


def test_gif_through_the_command_line(runs, capsys):
    out = runs["sine"] / "a.gif"
    assert main(["animate", str(runs["sine"]), "--out", str(out), "--max-frames", "5", "--exaggerate", "20"]) == 0
    assert "wrote" in capsys.readouterr().out
    from PIL import Image

    with Image.open(out) as im:
        assert im.format == "GIF" and im.size == (960, 480) and im.n_frames == 5
    assert not [p for p in out.parent.iterdir() if p.name.startswith(".a.")]  # no temporary file left


@pytest.mark.requires_ffmpeg
def test_mp4(runs, tmp_path):
    out = animate(runs["sine"], tmp_path / "run.mp4", exaggerate=20, fps=10, start_s=0.5, end_s=1.0)
    data = out.read_bytes()
    assert b"ftyp" in data[:16] and len(data) > 1000
    assert [p.name for p in tmp_path.iterdir()] == ["run.mp4"]


def test_mp4_without_imageio_says_what_to_install(runs, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import fails
    with pytest.raises(InputError, match=r"ehm\[animate\].*\.gif"):
        animate(runs["sine"], tmp_path / "run.mp4")
    assert not list(tmp_path.iterdir())


def test_errors(runs, tmp_path, capsys):
    with pytest.raises(InputError, match=r"has no poses.npz .*; write one with 'ehm simulate \.\.\. --out "):
        animate(tmp_path, tmp_path / "a.gif")
    assert main(["animate", str(tmp_path), "--out", str(tmp_path / "a.gif")]) == 2
    err = capsys.readouterr().err
    assert "has no poses.npz" in err and "Traceback" not in err
    with pytest.raises(InputError, match="unknown animation format"):
        animate(runs["sine"], tmp_path / "a.avi")
    for kwargs, what in (({"fps": 0}, "--fps"), ({"exaggerate": -1}, "--exaggerate"),
                         ({"exaggerate": float("nan")}, "--exaggerate"), ({"max_frames": 0}, "--max-frames"),
                         ({"start_s": 1.5, "end_s": 1.0}, "--end"), ({"start_s": 10.0}, "holds no poses")):
        with pytest.raises(InputError, match=what):
            animate(runs["sine"], tmp_path / "a.gif", **kwargs)
    assert not list(tmp_path.iterdir())  # nothing written on error


def test_auto_exaggeration_makes_the_motion_visible_and_says_so(runs, tmp_path, capsys):
    """`ehm animate RUN` without options: RUN/animation.gif, a factor that makes the motion visible (the 2 Hz,
    1 m/s^2 sine moves the body by millimetres: at true scale few pixels change), stated on the frames and the
    console, and a progress count on stderr; the run without input stays at true scale (nothing to show)."""
    from PIL import Image

    from ehm.outputs.animation import DEFAULT_NAME, auto_exaggeration, load_poses, motion_label, pick_exaggeration

    poses = load_poses(runs["sine"])
    factor = auto_exaggeration(poses)
    assert factor > 1 and f"{factor:g}"[0] in "125"  # one of 1, 2, 5 times a power of ten
    assert auto_exaggeration(load_poses(runs["still"])) == 1.0
    times = [0.0, 0.76, 1.24]
    true_scale = render_frames(runs["sine"], times_s=times, exaggerate=1)
    auto = render_frames(runs["sine"], times_s=times, exaggerate=factor)
    # the exaggerated frames change clearly more than the true-scale ones (measured 2282 against 1069 pixels: the
    # body on its soft back pads moves by some millimetres, a few pixels at true scale)
    assert _changed_body_pixels(auto[0], auto[1]) > 1.5 * max(1, _changed_body_pixels(true_scale[0], true_scale[1]))
    assert main(["animate", str(runs["sine"]), "--max-frames", "3"]) == 0
    captured = capsys.readouterr()
    out = runs["sine"] / DEFAULT_NAME
    drawn, why = pick_exaggeration(runs["sine"], max_frames=3)  # over the frames drawn: 0-0.08 s moves less
    assert drawn >= factor and why.startswith("chosen to make the motion visible: the largest, ")
    assert f"wrote {out}" in captured.out and f"motion x{drawn:g}, {why}" in captured.out
    with Image.open(out) as im:
        assert im.n_frames == 3
    assert "motion x" in motion_label(factor) and "true scale" in motion_label(1.0)
    seen = []
    animate(runs["sine"], tmp_path / "b.gif", max_frames=4, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(i, 4) for i in range(1, 5)]


def test_no_text_is_drawn_over_another(runs):
    """The clock and the motion's scale sit in a band below the axis labels: their boxes do not overlap any other
    text of the figure (the scale note was drawn over the front view's axis label)."""
    from ehm.outputs.animation import _Renderer, _scene, load_poses

    poses = load_poses(runs["sine"])
    scene = _scene(poses, np.arange(3), 20.0)
    r = _Renderer(poses, scene, 20.0, (960, 480), "a title")
    r.frame(0)
    renderer = r.canvas.get_renderer()
    texts = [t for t in r.fig.findobj(lambda a: hasattr(a, "get_text") and a.get_text() and a.get_visible())]
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in texts]
    for i, (a, box_a) in enumerate(boxes):
        for b, box_b in boxes[i + 1:]:
            assert not box_a.overlaps(box_b), (a, b)
    r.close()
