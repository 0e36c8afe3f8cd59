#pragma once
// A drawing of the 3D blade insertion (OpenCV imgproc; captions in Cairo text, sim/canvas.hpp):
// the scene and a rollout seen by a pinhole camera from a fixed world direction, and beside it
// the hand camera's depth images
// (sim/insert3d/camera.hpp) at the rollout's first and last pose (the first only for a scene).
//
//   left  : the block's five boxes (grey wireframe, the opening's corners orange), the blade's
//           outline every few steps (light to dark blue over time), the last blade green on
//           success, red on collision, grey otherwise; the hand origin's path; a caption;
//   right : the two depth images, 8x enlarged, near bright and far dark.
// The viewpoint looks from the world direction (1, -1.5, 1), 55 cm from the midpoint of the slot
// and the hand's start, world +z up on the page, so a rotated scene looks rotated.
#include <string>
#include <vector>

#include "handcentric/sim/draw.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"

namespace handcentric::experiments {

/// The scene and `rollout` (its world_T_hand may hold the start pose only: the scene alone),
/// with `caption` under it. Throws InvalidArgument for an empty rollout.
sim::Image draw_insert3d_rollout(const sim::insert3d::TaskScene& scene,
                                 const sim::insert3d::Rollout& rollout, const std::string& caption,
                                 const sim::insert3d::BladeSlotGeometry& geometry = {},
                                 const sim::insert3d::DepthCamera& camera = {});

/// The hand cameras' depth images along `rollout`, every `every`-th pose and the last, in rows of
/// `columns` panels (4x enlarged, near bright, each labelled with its step): what an image
/// policy saw. Each panel holds one image per camera of `rig`, the first on top. With `normals`,
/// each depth panel has the surface normals beside it, as the normals channels see them
/// (normals_from_depth): red = (1 + x) / 2, green = (1 + y) / 2 of the normal in the camera frame,
/// black where nothing is seen. Throws InvalidArgument for an empty rollout, every < 1, columns < 1
/// or an empty rig.
sim::Image draw_insert3d_camera_frames(
    const sim::insert3d::TaskScene& scene, const sim::insert3d::Rollout& rollout, int every = 4,
    int columns = 8, const sim::insert3d::BladeSlotGeometry& geometry = {},
    const std::vector<sim::insert3d::DepthCamera>& rig = {sim::insert3d::DepthCamera{}},
    bool normals = false);

}  // namespace handcentric::experiments
