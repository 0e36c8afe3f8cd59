"""handcentric.lerobot_policy: a policy with LeRobot's interface, audited as it is.

LeRobot's policies (huggingface/lerobot@005002bd315e0fbf7b44e18bc7100b659a30ceae:
src/lerobot/policies/diffusion/modeling_diffusion.py:DiffusionPolicy.select_action, .reset)
take one dict per control step, `{"observation.state": (B, S), "observation.images.<cam>":
(B, C, H, W)}`, and return one action (B, A) from `select_action`, keeping between calls the
observations of the last `n_obs_steps` steps and a queue of `n_action_steps` actions; `reset()`
starts an episode. audit_policy calls a function with keyword arguments (history, images,
scalars, ...) and reads back pose chunks. lerobot_policy(policy, ...) is the function between
the two, and nothing else: no geometry, no state of its own.

    history[:, 0] (the hand now, in state_format=) + scalars  -> batch[state]
    images[camera]                                            -> batch[images[camera]]
    select_action(batch), (B, A)  -> {name: (B, 1, width)} in the order of `action=`

Each entry of the returned dict is a chunk of one step (the step executed now), so that the
audit's outputs= says what it is: the pose entry in action_format=, the gripper "invariant".
Only the newest pose of the audit's history is passed: a LeRobot policy keeps its own past
(its `n_obs_steps` queue), so history=0 asks for no more. The audit's noise vector is not
passed: LeRobot's policies draw their own, which rng="torch" seeds alike for o and g o.
"""

from collections import OrderedDict


def _torch():
    import torch
    return torch


def lerobot_policy(policy, *, state="observation.state", scalars=(), images=None, action=None,
                   dtype="float32"):
    """A callable for audit_policy that asks `policy.select_action(batch)`.

    policy: has select_action(batch) -> (B, A) tensor (LeRobot's PreTrainedPolicy interface);
        pass its reset as audit_policy's reset=policy.reset, not here.
    state: the batch key of the state vector: the hand's pose now (history[:, 0], in the
        audit's state_format=, which must be a vector layout), then the audit's scalars named
        in `scalars`, in that order (e.g. ("gripper",), with audit_policy(scalars=["gripper"])).
    images: {audit camera: batch key}, e.g. {"eye_in_hand": "observation.images.wrist"}, with
        audit_policy(cameras=("eye_in_hand",)).
    action: {name: width}, the consecutive slices of the action vector, e.g. {"hand": 7,
        "gripper": 1}, whose names audit_policy's outputs= declares; None: the whole action is
        one pose (returned as a (B, 1, A) chunk, no dict).
    dtype: the torch dtype the batch is given in ("float32", LeRobot's; "float64").
    """
    if not callable(getattr(policy, "select_action", None)):
        raise TypeError("lerobot_policy: %r has no select_action(batch); for a function of "
                        "(history, ...) pass it to audit_policy directly" % (policy,))
    images = dict(images or {})
    slices = None
    if action is not None:
        slices, start = OrderedDict(), 0
        for name, width in dict(action).items():
            if int(width) < 1:
                raise ValueError("lerobot_policy: action[%r] = %r: a width of 1 or more"
                                 % (name, width))
            slices[name] = (start, start + int(width))
            start += int(width)
    scalars = tuple(scalars)

    def call(history, hand_points, world_points, noise, **keywords):
        if isinstance(history, dict):
            raise ValueError("lerobot_policy: a history per hand (%s): observation.state holds "
                             "one hand; audit without hands=" % ", ".join(history))
        torch = _torch()
        as_dtype = getattr(torch, dtype)

        def tensor(x):
            return torch.as_tensor(x).to(as_dtype)

        history = tensor(history)
        if history.ndim == 2:
            # One observation per call (no batch_size): LeRobot's batch axis of one.
            batched = False
            history = history[None]
        elif history.ndim == 3:
            batched = True
        else:
            raise ValueError("lerobot_policy: history of shape %s: the state is a vector, so "
                             "pass audit_policy a vector state_format= (e.g. 'pos_quat_wxyz')"
                             % (tuple(history.shape),))
        parts = [history[:, 0]]
        given = keywords.get("scalars") or {}
        for name in scalars:
            if name not in given:
                raise ValueError("lerobot_policy: scalar %r is not among the audit's scalars "
                                 "%s: pass audit_policy(scalars=[%r, ...])"
                                 % (name, sorted(given), name))
            parts.append(tensor(given[name]).reshape(-1, 1))
        batch = {state: torch.cat(parts, dim=1)}
        seen = keywords.get("images") or {}
        for camera, key in images.items():
            if camera not in seen:
                raise ValueError("lerobot_policy: camera %r is not among the audit's cameras "
                                 "%s: pass audit_policy(cameras=(%r, ...))"
                                 % (camera, sorted(seen), camera))
            image = tensor(seen[camera])
            batch[key] = image if batched else image[None]
        out = policy.select_action(batch)
        if out.ndim != 2 or out.shape[0] != history.shape[0]:
            raise ValueError("lerobot_policy: select_action returned shape %s for a batch of "
                             "%d: one action vector per row, (B, A)"
                             % (tuple(out.shape), history.shape[0]))
        if slices is None:
            chunk = out[:, None]
            return chunk if batched else chunk[0]
        end = max(b for _, b in slices.values())
        if out.shape[1] != end:
            raise ValueError("lerobot_policy: select_action returned %d numbers per action, "
                             "action=%s adds up to %d" % (out.shape[1], dict(action), end))
        result = {name: out[:, None, a:b] for name, (a, b) in slices.items()}
        return result if batched else {name: v[0] for name, v in result.items()}

    return call
