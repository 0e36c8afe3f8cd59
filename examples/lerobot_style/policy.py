"""A small torch policy of our own with LeRobot's interface, hand-centric by construction.

The interface mirrors huggingface/lerobot@005002bd315e0fbf7b44e18bc7100b659a30ceae:
src/lerobot/policies/diffusion/modeling_diffusion.py: DiffusionPolicy.select_action (one
dict of observations per step; the last n_obs_steps observations kept, the first one copied
to fill the queue; a chunk predicted when the action queue is empty, then one action popped per
call), DiffusionPolicy.reset (both queues emptied) and DiffusionModel.conditional_sample (the
initial noise drawn with torch.randn inside the policy). The code is ours, not LeRobot's.

    batch["observation.state"]         (B, 8): world_p_hand (3), world_q_hand (4, quaternion
                                       w, x, y, z: scalar first, as MuJoCo and PyTorch3D), gripper
    batch["observation.images.wrist"]  (B, C, H, W): a camera on the hand
    select_action(batch) -> (B, 8):    world_p_target, world_q_target (w, x, y, z), gripper

Hand-centric: every past hand pose is taken in the frame of the hand now (hand_T_past), the
wrist image is already in the hand's frame, the chunk is predicted in the frame of the hand at
the time of control (hand_T_target) and decoded to world poses with that hand pose (world_T_hand
hand_T_target) before it enters the queue. So the action does not depend on where the episode
is in the world, and the queue holds poses that moved with it.

fault= plants a symmetry breaking, for the audit to find:
    "world_state":    the network also reads world_p_hand and world_q_hand (NO under
                      translation, in every single call);
    "world_velocity": the hand's motion since the previous observation is read as a world-frame
                      displacement world_p_now - world_p_past instead of hand_p_past. After
                      reset() the queue holds one observation copied, so the displacement is 0
                      and every single call is equivariant; only a rollout moves the hand, so
                      only the closed loop sees it (NO under rotation, yes under translation).
"""
from collections import deque

import torch
from torch import nn

STATE = "observation.state"
WRIST = "observation.images.wrist"
FAULTS = (None, "world_state", "world_velocity")
_STEP = 0.05  # m: the size of one predicted step in the hand frame, before tanh


def quat_to_matrix(q):
    """(..., 4) quaternion w, x, y, z (any norm) -> (..., 3, 3) rotation."""
    w, x, y, z = (q / q.norm(dim=-1, keepdim=True)).unbind(-1)
    return torch.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], dim=-1).reshape(q.shape[:-1] + (3, 3))


def matrix_to_quat(rotation):
    """(..., 3, 3) rotation -> (..., 4) unit quaternion w, x, y, z with w >= 0. Each of the four
    candidates divides by its own largest term, so the one picked is accurate at every angle
    (Shepperd's method)."""
    m = rotation
    m00, m01, m02 = m[..., 0, 0], m[..., 0, 1], m[..., 0, 2]
    m10, m11, m12 = m[..., 1, 0], m[..., 1, 1], m[..., 1, 2]
    m20, m21, m22 = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    candidates = torch.stack([
        torch.stack([1 + m00 + m11 + m22, m21 - m12, m02 - m20, m10 - m01], -1),
        torch.stack([m21 - m12, 1 + m00 - m11 - m22, m01 + m10, m02 + m20], -1),
        torch.stack([m02 - m20, m01 + m10, 1 - m00 + m11 - m22, m12 + m21], -1),
        torch.stack([m10 - m01, m02 + m20, m12 + m21, 1 - m00 - m11 + m22], -1),
    ], dim=-2)
    diagonal = torch.stack([candidates[..., i, i] for i in range(4)], -1)
    best = diagonal.argmax(-1)
    q = torch.gather(candidates, -2, best[..., None, None].expand(best.shape + (1, 4)))[..., 0, :]
    q = q / q.norm(dim=-1, keepdim=True)
    return torch.where(q[..., :1] < 0, -q, q)


def rot6d_rows_to_matrix(six):
    """(..., 6): the first two rows of R, not yet orthonormal -> (..., 3, 3) (Gram-Schmidt)."""
    a, b = six[..., :3], six[..., 3:]
    row0 = a / a.norm(dim=-1, keepdim=True)
    b = b - (row0 * b).sum(-1, keepdim=True) * row0
    row1 = b / b.norm(dim=-1, keepdim=True)
    return torch.stack([row0, row1, torch.linalg.cross(row0, row1)], dim=-2)


def pose(position, rotation):
    """(..., 3), (..., 3, 3) -> (..., 4, 4)."""
    out = torch.zeros(position.shape[:-1] + (4, 4), dtype=position.dtype)
    out[..., :3, :3] = rotation
    out[..., :3, 3] = position
    out[..., 3, 3] = 1
    return out


def inverse(world_T_frame):
    rotation, position = world_T_frame[..., :3, :3], world_T_frame[..., :3, 3]
    rotation_t = rotation.transpose(-1, -2)
    return pose(-(rotation_t @ position[..., None])[..., 0], rotation_t)


class HandCentricPolicy(nn.Module):
    """select_action(batch) -> (B, 8); reset(). Weights drawn from `seed` (untrained: the audit
    is of the architecture and its frames, which training does not change)."""

    name = "hand_centric_example"

    def __init__(self, n_obs_steps=2, horizon=8, n_action_steps=4, channels=4, fault=None,
                 seed=0):
        super().__init__()
        if fault not in FAULTS:
            raise ValueError("fault=%r: one of %s" % (fault, FAULTS))
        if not 1 <= n_action_steps <= horizon:
            raise ValueError("n_action_steps=%d: from 1 to horizon=%d" % (n_action_steps, horizon))
        self.n_obs_steps, self.horizon, self.n_action_steps = n_obs_steps, horizon, n_action_steps
        self.fault = fault
        # Per observation step: hand_T_past as position + 6D rows (9), the gripper (1), the
        # image's features (8); the "world_state" fault adds world_p_hand, world_q_hand (7).
        per_step = 9 + 1 + 8 + (7 if fault == "world_state" else 0)
        self.noise_size = horizon * 10  # per step: position (3), 6D rows (6), gripper (1)
        with torch.random.fork_rng():  # the weights from `seed`, the global generator untouched
            torch.manual_seed(seed)
            self.image_encoder = nn.Sequential(
                nn.Conv2d(channels, 8, kernel_size=5, stride=4), nn.ReLU(),
                nn.AdaptiveAvgPool2d(1), nn.Flatten())
            self.head = nn.Sequential(
                nn.Linear(n_obs_steps * per_step + self.noise_size, 128), nn.Tanh(),
                nn.Linear(128, self.noise_size))
        self.eval()
        self.reset()

    def reset(self):
        """Empty the observation and action queues: call at the start of every episode."""
        self._observations = deque(maxlen=self.n_obs_steps)
        self._actions = deque(maxlen=self.n_action_steps)

    @torch.no_grad()
    def select_action(self, batch):
        state = batch[STATE].to(torch.float64)  # the frames in float64, the network in float32
        world_T_hand = pose(state[:, :3], quat_to_matrix(state[:, 3:7]))
        observation = (world_T_hand, state[:, 7:8], state[:, :7],
                       self.image_encoder(batch[WRIST].to(torch.float32)))
        # LeRobot's populate_queues: the first observation of an episode fills the queue.
        while len(self._observations) < self.n_obs_steps - 1:
            self._observations.append(observation)
        self._observations.append(observation)
        if not self._actions:
            chunk = self._predict_chunk(world_T_hand)
            self._actions.extend(chunk[:, :self.n_action_steps].transpose(0, 1))
        return self._actions.popleft()

    def _predict_chunk(self, world_T_hand):
        """(B, horizon, 8) world-frame actions, predicted in the frame of the hand now."""
        hand_T_world = inverse(world_T_hand)
        features = []
        for world_T_past, gripper, world_state, image_features in self._observations:
            hand_T_past = hand_T_world @ world_T_past
            if self.fault == "world_velocity":
                # The fault: the displacement in world axes, which turns with g.
                moved = world_T_hand[:, :3, 3] - world_T_past[:, :3, 3]
            else:
                moved = hand_T_past[:, :3, 3]
            features += [moved, hand_T_past[:, :2, :3].reshape(-1, 6), gripper, image_features]
            if self.fault == "world_state":
                features.append(world_state)
        batch_size = world_T_hand.shape[0]
        # The policy's own noise (as LeRobot's conditional_sample draws it): audit with rng=.
        noise = torch.randn(batch_size, self.noise_size, dtype=torch.float32)
        inputs = torch.cat([f.to(torch.float32) for f in features] + [noise], dim=1)
        out = self.head(inputs).to(torch.float64).reshape(batch_size, self.horizon, 10)
        hand_T_target = pose(_STEP * torch.tanh(out[..., :3]),
                             rot6d_rows_to_matrix(out[..., 3:9] + torch.tensor(
                                 [1, 0, 0, 0, 1, 0], dtype=torch.float64)))
        world_T_target = world_T_hand[:, None] @ hand_T_target
        gripper = torch.sigmoid(out[..., 9:])
        return torch.cat([world_T_target[..., :3, 3], matrix_to_quat(world_T_target[..., :3, :3]),
                          gripper], dim=-1).to(torch.float32)
