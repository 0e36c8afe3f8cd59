#pragma once
// RecordedObservations: a user's own observations (a dataset's frames, a robot's log), which the
// audit draws its cases from instead of random scenes. A policy is meant for the poses of its
// data; asked about g only on scenes it never sees (10 m away, 1e3 m edge cases), it may fail
// for reasons its users do not care about, or pass where its data would show a leak.
//
// Each observation declares, by where each of its parts sits, what g does to it (Sec. 2.2):
//
//   history        (H+1, 4, 4) world_T_hand, [0] the hand now          moves: T -> g T
//   chunk          (K, 4, 4) world_T_hand, optional (a representation's
//                  actions encode it; a whole policy does not read it)  moves
//   world_points   (m, 3) world frame, optional                         moves: x -> g x
//   extra_poses    {name: (4, 4)} world frame (a goal, the start pose)  moves
//   hand_points    (n, 3) hand frame, optional                          held fixed
//   scalars        {name: number} (a gripper's width)                   held fixed
//   held           {name: array} (a wrist camera's image, token ids)    held fixed
//   episode        an integer, optional: the recorded episode the observation belongs to
//
// With several hands, history is one per hand, {hand: (H+1, 4, 4)} ("history/NAME" in a .npz),
// each moving with g (observation/hands.hpp says how a scene carries them).
//
// An episode index (every observation's, or none) makes the observations episodes for the
// closed loop (checks/recorded_episodes.hpp): the observations of one episode together and in
// their order, the episodes in the order they first appear; an index that comes back after
// another episode's observations is an error, not a new episode.
//
// Held fixed is the eye-in-hand assumption of Theorem 1: what moves with the hand looks the same
// in o and g o. An array that is in fact world-frame (a third-person image, an object position)
// must not be declared held: the audit would then check a symmetry the data do not have
// (tests/props/test_recorded.cpp shows the verdict such a declaration changes).
//
// Files (read_observations): JSON Lines, one observation per line, the names above as keys,
// arrays as nested lists or the pipe's encoded arrays {"dtype", "shape", "data"}; or NumPy's
// .npz (np.savez or np.savez_compressed), one array per part with the observations along a
// leading axis: "history" (N, H+1, 4, 4), "chunk", "hand_points", "world_points",
// "extra_poses/NAME" (N, 4, 4), "scalars/NAME" (N,), "held/NAME" (N, ...), "episode" (N,)
// integers, "history/NAME" (N, H+1, 4, 4) per hand. docs/AUDIT.md,
// "Your own observations".
#include <cstddef>
#include <cstdint>
#include <istream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/scene.hpp"
#include "handcentric/props/observation/workspace.hpp"

namespace handcentric::props {

/// One recorded episode: its index as recorded and where its observations are.
struct RecordedEpisode {
  std::int64_t index = 0;  ///< the "episode" value its observations carry
  std::size_t first = 0;   ///< its first observation in RecordedObservations::scenes
  std::size_t steps = 0;   ///< how many observations it has, in order
};

struct RecordedObservations {
  std::vector<Scene> scenes;  ///< world frame; a scene without a recorded chunk has T_1 = T_0
  bool has_chunks = false;    ///< every observation recorded its chunk
  std::string source;         ///< "data.jsonl", "a Python iterable"
  /// Each observation's "episode", or empty when the data record none.
  std::vector<std::int64_t> episode;

  /// The recorded episodes in the order they appear (empty without an episode index).
  std::vector<RecordedEpisode> episodes() const;

  /// The hands whose histories are recorded one per hand, sorted; empty with one history.
  std::vector<std::string> hands() const;

  /// Throws InvalidArgument naming the observation, the part and the fix: none at all; a part
  /// that is not finite or not a rigid transform; names (extra poses, scalars, held arrays) that
  /// differ from the first observation's (every observation carries the same, in one order); an
  /// episode index of another length than scenes, or whose episode comes back after another's.
  void validate() const;

  /// Whether some observation has world points (the third-person view has something to move).
  bool has_world_points() const;

  /// "cases drawn from 250 recorded observations (data.jsonl), each with a random g".
  std::string verdict_note() const;

  /// Throws InvalidArgument naming the first observation outside `box` and the fix.
  void require_inside(const Workspace& box) const;
};

/// Reads a .jsonl (or .json-lines, .ndjson) or .npz file, by its extension, and validates it.
/// Throws FileError (cannot open, truncated, not a zip, a compression other than stored or
/// deflate) or InvalidArgument (a bad line or array), naming the file, the line or array, and
/// the fix. The files' sizes are bounded (kMaxRecordedBytes) before anything large is allocated.
RecordedObservations read_observations(const std::string& path);

/// JSON Lines from a stream; `source` names it in messages. Blank lines are skipped.
RecordedObservations observations_from_json_lines(std::istream& in, const std::string& source);

/// One part of one observation as numbers (what a file or a Python dict holds).
struct RecordedPart {
  std::vector<std::int64_t> shape;
  std::vector<double> values;  ///< row-major
  bool float32 = false;        ///< a held array handed over as float32 (an image)
};

/// One observation from its parts, keyed "history" (or "history/HAND" per hand), "chunk",
/// "hand_points", "world_points", "extra_poses/NAME", "scalars/NAME", "held/NAME" (a std::map:
/// names in one sorted order); "episode" is not a part of the scene (take it with episode_of).
/// Poses need a last row (0, 0, 0, 1) to 1e-6 and a rotation block orthonormal to 1e-5 (a
/// float32 dataset's are to ~1e-7), which is projected onto the nearest rotation so that g T is
/// a rigid transform. Throws InvalidArgument naming `where`, the part and the fix. A scene
/// without a chunk comes back without one (recorded_observations gives it T_1 = T_0).
Scene recorded_observation(const std::map<std::string, RecordedPart>& parts,
                           const std::string& where);

/// Removes the part "episode" from `parts` and returns it: nullopt when absent. Throws
/// InvalidArgument naming `where` and the value when it is not one integer.
std::optional<std::int64_t> episode_of(std::map<std::string, RecordedPart>& parts,
                                       const std::string& where);

/// The observations, each without a chunk given T_1 = T_0 (a whole policy never reads it; a
/// representation audit refuses data whose has_chunks is false), with their episode index
/// (empty, or one per scene: some with and some without is an error naming the first without),
/// validated.
RecordedObservations recorded_observations(
    std::vector<Scene> scenes, std::string source,
    const std::vector<std::optional<std::int64_t>>& episode = {});

/// The largest file (or decompressed .npz member) read_observations accepts: 4 GiB.
inline constexpr std::size_t kMaxRecordedBytes = std::size_t{1} << 32;

}  // namespace handcentric::props
