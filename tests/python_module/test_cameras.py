"""Cameras in the audit (cameras=, image_size=, channels=, floor=): the images a policy sees,
invariant on the hand and not in the world; a torch CNN on the eye-in-hand image inside a
hand-centric policy is equivariant, the same CNN on the third-person image is not."""
import numpy as np
import pytest

import handcentric


def pose(angle, axis, translation):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    T = np.eye(4)
    T[:3, :3] = handcentric.so3_exp(angle * axis)
    T[:3, 3] = translation
    return T


HISTORY = pose(0.7, [1, 2, 3], [0.4, -0.2, 0.5])[None]
HAND_POINTS = np.array([[0.02, 0.01, 0.3], [-0.05, 0.03, 0.5]])
WORLD_POINTS = np.array([[0.3, 0.1, 0.2], [-0.2, 0.4, 0.1]])
G_SE3 = pose(2.1, [0.3, -1, 0.4], [3.0, -1.0, 2.0])
G_SE2 = pose(0.9, [0, 0, 1], [0.7, -0.4, 0.0])


def images(g=np.eye(4), **kw):
    return handcentric.render_cameras(g @ HISTORY, HAND_POINTS,
                                      (WORLD_POINTS @ g[:3, :3].T) + g[:3, 3], **kw)


def test_the_eye_in_hand_image_does_not_change_with_g_the_third_person_image_does():
    both = ("eye_in_hand", "third_person")
    before, after = images(cameras=both), images(G_SE2, cameras=both)
    assert before["eye_in_hand"].shape == (4, 48, 64)
    assert before["eye_in_hand"].dtype == np.float32
    assert before["eye_in_hand"][3].min() < 1.0  # the points are in view
    assert np.abs(after["eye_in_hand"] - before["eye_in_hand"]).max() < 1e-6
    assert before["third_person"][3].min() < 5.0  # the world points are in its view too
    assert np.abs(after["third_person"] - before["third_person"]).max() > 0.1
    moved = images(G_SE3, cameras="eye_in_hand")["eye_in_hand"]
    assert np.abs(moved - before["eye_in_hand"]).max() < 1e-6


def test_with_the_floor_the_eye_in_hand_image_keeps_se2_only():
    kw = dict(cameras="eye_in_hand", floor=True, image_size=(32, 24), channels="depth")
    before = images(**kw)["eye_in_hand"]
    assert before.shape == (1, 24, 32)
    assert np.abs(images(G_SE2, **kw)["eye_in_hand"] - before).max() < 1e-6
    assert np.abs(images(G_SE3, **kw)["eye_in_hand"] - before).max() > 0.01


torch = pytest.importorskip("torch")


class CnnPolicy(torch.nn.Module):
    """A small CNN on one camera's image, its output a translation per step in the hand frame:
    T_k = T_0 [I, p_k] (eq. 1's decoding), so equivariant exactly when the image is invariant."""

    def __init__(self, camera, chunk=2):
        super().__init__()
        torch.manual_seed(0)
        self.camera, self.chunk = camera, chunk
        self.net = torch.nn.Sequential(
            torch.nn.Conv2d(4, 8, 5, stride=2), torch.nn.SiLU(),
            torch.nn.Conv2d(8, 8, 3, stride=2), torch.nn.SiLU(),
            torch.nn.AdaptiveAvgPool2d(2), torch.nn.Flatten(), torch.nn.Linear(32, 3 * chunk))

    def forward(self, history, hand_points, world_points, noise, images):
        steps = self.net(images[self.camera]).double().reshape(-1, self.chunk, 3)
        steps = steps + 0.01 * noise[:, :1, None]
        local = torch.eye(4, dtype=torch.float64).repeat(len(steps), self.chunk, 1, 1)
        local[:, :, :3, 3] = steps
        return history[:, :1] @ local


def audit(camera, view):
    return handcentric.assert_equivariant(
        CnnPolicy(camera), "se3", views=(view,), cameras=(camera,), cases=40, batch_size=64,
        array="torch", noise=1, chunk=2, hand_points=2, quiet=True)


def test_a_cnn_on_the_eye_in_hand_image_is_equivariant():
    with torch.no_grad():
        audit("eye_in_hand", "eye_in_hand")


def test_mutant_the_same_cnn_on_the_third_person_image_is_not():
    with torch.no_grad(), pytest.raises(AssertionError, match="se3"):
        audit("third_person", "third_person")


@pytest.mark.parametrize("kw, message", [
    (dict(cameras="wrist"), "eye_in_hand"),
    (dict(cameras="eye_in_hand", image_size=(0, 48)), "image width=0"),
    (dict(cameras="eye_in_hand", image_size=(64,)), "two numbers"),
    (dict(cameras="eye_in_hand", channels="bgr"), "rgbd"),
    (dict(floor=True), "cameras=None"),
    (dict(cameras="eye_in_hand", image_size=(1024, 1024), batch_size=64), "2\\*\\*26"),
])
def test_bad_camera_arguments_are_refused_in_one_line(kw, message):
    with pytest.raises(ValueError, match=message):
        handcentric.audit_policy(lambda *a, **k: None, cases=1, quiet=True, **kw)
