#pragma once
// The --exec protocol's messages (docs/AUDIT.md, "--exec"): requests written as JSON Lines,
// replies parsed and validated. No I/O here: subprocess.hpp moves the bytes.
//
// Version 2 (every request carries "protocol": 2; a version-1 plug-in ignores that field):
//   encode : {"id", "protocol", "history", "chunk", "hand_points", "world_points"
//             [, "extra_poses": {name: [16]}, "scalars": {name: x}] [, "eps": [...], "t": x]}
//            -> {"id", "actions" [, "observation"] [, "flow_input", "flow_target"]}
//   decode : {"id", "protocol", "decode": [actions], "history", "hand_points", "world_points"
//             [, extras]} -> {"id", "chunk": [[16], ...]}
//   policy : {"id", "protocol", "history", "hand_points", "world_points" [, extras],
//             "noise": [numbers]} -> {"id", "chunk": [[16], ...]}   (a whole policy, eq. 4)
//   hello  : a plug-in may answer the first request it reads with
//            {"id", "hello": {"protocol": 2, "extra_poses": [names], "scalars": [names],
//             "decode": bool, "flow": bool, "noise": n, "batch": B}} instead; the audit then
//            asks again.
//   batch  : after a hello with "batch": B, every encode and policy request (not decode, not
//            flow) is {"id", "protocol", "batch": [{fields of one request}, ...]} with 1 to B
//            scenes of any shapes -> {"id", "batch": [{fields of one answer}, ...]}, in order.
//   base64 : a hello with "batch" and "encodings": [..., "base64", ...] gets its batched lines
//            as {"id", "protocol", "encoding": "base64", "batch": [...]}, each array of numbers
//            in them {"dtype": "float64", "shape": [...], "data": base64 of the little-endian
//            bytes} (history [H+1, 4, 4], points [n, 3], an extra pose [4, 4], noise [d];
//            scalars stay numbers); an answer's arrays may take the same form (actions [a],
//            a chunk [K, 4, 4]). Without the offer, lines are as they were, byte for byte.
// Matrices are 16 numbers, row-major 4x4.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/observation/camera_rig.hpp"
#include "handcentric/props/transport/policy_interface.hpp"
#include "handcentric/props/transport/subprocess.hpp"

namespace handcentric::props {

constexpr int kProtocolVersion = 2;
/// The deepest JSON nesting a reply may have (a reply needs 3: object, chunk, pose).
constexpr int kMaxReplyDepth = 32;

/// How the arrays of numbers of a batched line are written: JSON numbers, or encoded arrays
/// (docs/AUDIT.md, "Encoded numbers"), when the plug-in's hello offers "base64".
enum class NumberEncoding { text, base64 };

/// What a plug-in said about itself in its hello (or what flags asked for).
struct PluginCapabilities {
  int protocol = 1;
  std::vector<std::string> extra_pose_names;
  std::vector<std::string> scalar_names;
  bool decode = false;
  bool flow = false;
  int noise = 0;  ///< a policy's noise length; 0: the default (kPolicyNoise)
  int batch = 0;  ///< the most scenes per batched request; 0: one request per scene
  /// The encoding of batched lines: base64 when the hello's "encodings" offers it.
  NumberEncoding encoding = NumberEncoding::text;
  /// A policy that sees cameras (hello "cameras": {"views": [...], "image_size": [w, h],
  /// "channels": "rgbd", "floor": false}): each policy request then carries "images": {view:
  /// float32 array (C, h, w) in the base64 form}, rendered by this rig.
  std::optional<CameraRig> cameras;
  /// A policy's layouts, outputs, hands, rng and episodes (policy_interface.hpp).
  PolicyInterface policy;
};

/// The noise a policy request carries unless the plug-in's hello asks for another length.
constexpr int kPolicyNoise = 256;
/// The longest noise vector a policy may read (a plug-in's hello "noise", the Python module's
/// noise=); a longer one is refused with an error naming it. 65536 numbers cover a sampler that
/// draws fresh noise at every step (100 DDPM steps x 16 poses x 10 numbers = 16000) four times
/// over, while the in-distribution check's Jacobian of a chunk of K poses, 12 K x noise
/// doubles, stays at 100 MB for K = 16 (a length of 10^9 would ask for 8 GB per vector).
constexpr int kMaxPolicyNoise = 65536;

/// The noise and time of a flow request.
struct FlowQuery {
  const Eigen::VectorXd* eps = nullptr;
  double t = 0.0;
};

/// The body of an encode request (everything after the id). A flow query is always text.
std::string encode_request_body(const Scene& scene,
                                const std::optional<FlowQuery>& flow = std::nullopt,
                                NumberEncoding encoding = NumberEncoding::text);
/// The body of a decode request: the observation (no chunk) and the actions to decode.
std::string decode_request_body(const Eigen::VectorXd& actions, const Scene& observation);
/// The body of a policy request: the observation (no chunk) and the noise.
/// With `interface`, its poses are written as it declares (policy_interface.hpp); with `episode`,
/// the request carries "episode": {"index", "step"}.
std::string policy_request_body(const Scene& observation, const Eigen::VectorXd& noise,
                                NumberEncoding encoding = NumberEncoding::text,
                                const PolicyInterface* interface = nullptr,
                                const EpisodeStep* episode = nullptr);
/// The body of a batched request: "batch": [{body}, {body}, ...], each body as the single
/// request's (written in `encoding`, which the line then names: "encoding": "base64").
std::string batch_request_body(const std::vector<std::string>& bodies,
                               NumberEncoding encoding = NumberEncoding::text);
/// The scene's numbers, counts and names as raw bytes: two scenes have the same key exactly
/// when their requests would be the same, and it costs a copy where a request formats every
/// number (the caches' key). `with_chunk` false: the observation only (a policy request's).
std::string scene_key(const Scene& scene, bool with_chunk = true);
/// The whole line: {"id": id, "protocol": 2, <body>}\n.
std::string request_line(int id, const std::string& body);

/// A parsed reply. Exactly one of hello / encode / chunk is filled, as the request asked.
struct PluginReply {
  std::optional<PluginCapabilities> hello;
  Eigen::VectorXd actions, observation, flow_input, flow_target;
  bool has_observation = false, has_flow = false;
  std::vector<RigidTransform> chunk;  ///< decode and policy replies
  /// A policy reply read under a PolicyInterface with named outputs or an action layout: every
  /// output, in the interface's order (`chunk` is the first when there is one output).
  std::vector<OutputValue> outputs;
  /// A policy_stages reply: each stage's value, in the hello's "stages" order.
  std::vector<OutputValue> stages;
};

/// policy_stages: a policy request that carries "stages": true, answered as a policy request
/// plus "stages": {name: value} for every stage its hello declares (policy_interface.hpp).
enum class RequestKind { encode, flow, decode, policy, policy_stages };

/// Parses and validates `line` as the reply to request `id` of `kind`; `who` names the plug-in
/// in messages. Throws PluginError with a one-line message for anything else: not JSON, nested
/// deeper than kMaxReplyDepth, a non-finite number, a wrong id, a missing field, a matrix that
/// is not 16 finite numbers with last row 0 0 0 1.
/// A policy reply is read under `interface` when given (its action layout, its outputs).
PluginReply parse_reply(const std::string& line, int id, RequestKind kind, const std::string& who,
                        bool hello_allowed, const PolicyInterface* interface = nullptr);
/// Parses the reply to batched request `id` of `count` scenes: {"id", "batch": [answers]}, each
/// answer checked as parse_reply checks one, a message naming the item. Each array of an answer
/// may be JSON numbers or an encoded array (float64 of shape [n]; a chunk [K, 4, 4]). Throws
/// PluginError for a reply without "batch", a count other than `count`, or a bad item: for an
/// encoded array, malformed base64, a length that is not the shape's, a dtype other than
/// float64, a shape other than the field's, or a non-finite number.
std::vector<PluginReply> parse_batch_reply(const std::string& line, int id, RequestKind kind,
                                           const std::string& who, std::size_t count,
                                           const PolicyInterface* interface = nullptr);

/// Throws InvalidArgument naming `flag` for an empty or repeated name.
void require_distinct_names(const std::vector<std::string>& names, const std::string& flag);
/// `first` followed by the names of `second` it lacks (a hello's names, then a flag's).
std::vector<std::string> merged_names(std::vector<std::string> first,
                                      const std::vector<std::string>& second);

/// A scene with an identity pose and a zero for each name it lacks (the handshake's probe).
Scene with_named_extras(Scene scene, const std::vector<std::string>& pose_names,
                        const std::vector<std::string>& scalar_names);

}  // namespace handcentric::props
