#include "handcentric/policy/config.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <sstream>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::policy {

std::string to_string(HeadKind kind) {
  switch (kind) {
    case HeadKind::flow:
      return "flow";
    case HeadKind::ddpm:
      return "ddpm";
    case HeadKind::cvae:
      return "cvae";
    case HeadKind::c8flow:
      return "c8flow";
    case HeadKind::c8ddpm:
      return "c8ddpm";
    case HeadKind::c8flow_planar:
      return "c8flow_planar";
    case HeadKind::c8ddpm_avg:
      return "c8ddpm_avg";
    case HeadKind::c8flow_avg:
      return "c8flow_avg";
  }
  return "?";
}

HeadKind parse_head(const std::string& name) {
  for (HeadKind kind :
       {HeadKind::flow, HeadKind::ddpm, HeadKind::cvae, HeadKind::c8flow, HeadKind::c8ddpm,
        HeadKind::c8flow_planar, HeadKind::c8ddpm_avg, HeadKind::c8flow_avg}) {
    if (to_string(kind) == name) return kind;
  }
  throw InvalidArgument(
      "unknown head '" + name +
      "': use one of flow, ddpm, cvae, c8flow, c8ddpm, c8flow_planar, c8ddpm_avg, c8flow_avg");
}

bool is_c8_planar(HeadKind kind) {
  return kind == HeadKind::c8ddpm || kind == HeadKind::c8flow_planar ||
         kind == HeadKind::c8ddpm_avg || kind == HeadKind::c8flow_avg;
}

HeadKind trained_as(HeadKind kind) {
  if (kind == HeadKind::c8ddpm_avg) return HeadKind::c8ddpm;
  if (kind == HeadKind::c8flow_avg) return HeadKind::c8flow_planar;
  return kind;
}

std::string to_string(Activation activation) {
  return activation == Activation::silu ? "silu" : "relu";
}

Activation parse_activation(const std::string& name) {
  if (name == "silu") return Activation::silu;
  if (name == "relu") return Activation::relu;
  throw InvalidArgument("unknown activation '" + name + "': use silu or relu");
}

std::string to_string(LearningRateSchedule schedule) {
  return schedule == LearningRateSchedule::cosine ? "cosine" : "constant";
}

LearningRateSchedule parse_schedule(const std::string& name) {
  if (name == "constant") return LearningRateSchedule::constant;
  if (name == "cosine") return LearningRateSchedule::cosine;
  throw InvalidArgument("unknown learning-rate schedule '" + name + "': use constant or cosine");
}

std::string to_string(DdpmPrediction prediction) {
  return prediction == DdpmPrediction::sample ? "sample" : "epsilon";
}

std::string to_string(ObservationKind kind) {
  return kind == ObservationKind::image ? "image" : "key_points";
}

ObservationKind parse_observation(const std::string& name) {
  if (name == "key_points") return ObservationKind::key_points;
  if (name == "image") return ObservationKind::image;
  throw InvalidArgument("unknown observation '" + name + "': use key_points or image");
}

std::string to_string(ImageFeatures features) {
  return features == ImageFeatures::spatial_softmax ? "spatial_softmax" : "flatten";
}

ImageFeatures parse_image_features(const std::string& name) {
  if (name == "flatten") return ImageFeatures::flatten;
  if (name == "spatial_softmax") return ImageFeatures::spatial_softmax;
  throw InvalidArgument("unknown image features '" + name + "': use flatten or spatial_softmax");
}

DdpmPrediction parse_ddpm_prediction(const std::string& name) {
  if (name == "epsilon") return DdpmPrediction::epsilon;
  if (name == "sample") return DdpmPrediction::sample;
  throw InvalidArgument("unknown DDPM prediction '" + name + "': use epsilon or sample");
}

namespace {

void require(bool ok, const std::string& field, const std::string& value,
             const std::string& range) {
  if (!ok)
    throw InvalidArgument("policy config: " + field + " = " + value + " is out of range: use " +
                          range);
}

// One entry per stored field: how to print it and how to parse it.
struct Field {
  std::string key;
  std::function<std::string(const PolicyConfig&)> get;
  std::function<void(PolicyConfig&, const std::string&)> set;
};

int parse_int(const std::string& key, const std::string& text) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) {
    throw InvalidArgument("policy config: " + key + " = '" + text + "' is not an integer");
  }
  return value;
}

double parse_double(const std::string& key, const std::string& text) {
  std::istringstream in(text);
  double value = 0.0;
  in >> value;
  if (!in || !in.eof() || !std::isfinite(value)) {
    throw InvalidArgument("policy config: " + key + " = '" + text + "' is not a finite number");
  }
  return value;
}

// clang-format off
#define HC_INT_FIELD(name)                                                              \
  Field{#name, [](const PolicyConfig& c) { return std::to_string(c.name); },           \
        [](PolicyConfig& c, const std::string& v) { c.name = parse_int(#name, v); }}
#define HC_DOUBLE_FIELD(name)                                                           \
  Field{#name, [](const PolicyConfig& c) { return format_number(c.name); },            \
        [](PolicyConfig& c, const std::string& v) { c.name = parse_double(#name, v); }}
// clang-format on

const std::vector<Field>& fields() {
  static const std::vector<Field> all = {
      Field{"task", [](const PolicyConfig& c) { return c.task; },
            [](PolicyConfig& c, const std::string& v) { c.task = v; }},
      Field{"head", [](const PolicyConfig& c) { return to_string(c.head); },
            [](PolicyConfig& c, const std::string& v) { c.head = parse_head(v); }},
      Field{"representation", [](const PolicyConfig& c) { return c.representation; },
            [](PolicyConfig& c, const std::string& v) { c.representation = v; }},
      HC_INT_FIELD(chunk_length),
      HC_INT_FIELD(history_length),
      HC_INT_FIELD(hand_points),
      HC_INT_FIELD(world_points),
      HC_INT_FIELD(action_dimension),
      HC_INT_FIELD(observation_dimension),
      HC_INT_FIELD(hidden_width),
      HC_INT_FIELD(hidden_layers),
      Field{"activation", [](const PolicyConfig& c) { return to_string(c.activation); },
            [](PolicyConfig& c, const std::string& v) { c.activation = parse_activation(v); }},
      HC_INT_FIELD(time_embedding),
      HC_INT_FIELD(steps),
      HC_INT_FIELD(batch_size),
      HC_DOUBLE_FIELD(learning_rate),
      Field{"lr_schedule", [](const PolicyConfig& c) { return to_string(c.lr_schedule); },
            [](PolicyConfig& c, const std::string& v) { c.lr_schedule = parse_schedule(v); }},
      HC_DOUBLE_FIELD(weight_decay),
      HC_DOUBLE_FIELD(gradient_clip),
      HC_DOUBLE_FIELD(ema_decay),
      HC_INT_FIELD(euler_steps),
      HC_INT_FIELD(ddpm_train_steps),
      HC_INT_FIELD(ddim_steps),
      Field{"ddpm_prediction", [](const PolicyConfig& c) { return to_string(c.ddpm_prediction); },
            [](PolicyConfig& c, const std::string& v) {
              c.ddpm_prediction = parse_ddpm_prediction(v);
            }},
      HC_INT_FIELD(cvae_latent),
      HC_DOUBLE_FIELD(cvae_kl_weight),
      HC_DOUBLE_FIELD(noise_scale),
      HC_INT_FIELD(execute),
      HC_DOUBLE_FIELD(c8_centre_x),
      HC_DOUBLE_FIELD(c8_centre_y),
      Field{"observation", [](const PolicyConfig& c) { return to_string(c.observation); },
            [](PolicyConfig& c, const std::string& v) { c.observation = parse_observation(v); }},
      HC_INT_FIELD(image_channels),
      HC_INT_FIELD(image_height),
      HC_INT_FIELD(image_width),
      Field{"encoder", [](const PolicyConfig& c) { return c.encoder; },
            [](PolicyConfig& c, const std::string& v) { c.encoder = v; }},
      Field{"image_features", [](const PolicyConfig& c) { return to_string(c.image_features); },
            [](PolicyConfig& c, const std::string& v) {
              c.image_features = parse_image_features(v);
            }},
      HC_DOUBLE_FIELD(image_fov_deg),
      HC_INT_FIELD(image_cameras),
  };
  return all;
}

#undef HC_INT_FIELD
#undef HC_DOUBLE_FIELD

}  // namespace

namespace {
constexpr int kMaxPoints = 1 << 16;
constexpr int kMaxDimension = 1 << 20;
}  // namespace

void PolicyConfig::validate() const {
  const auto s = [](auto v) { return std::to_string(v); };
  require(task == kTaskPeg2d || task == kTaskInsert3d, "task", "'" + task + "'",
          "peg2d or insert3d");
  require(chunk_length >= 1 && chunk_length <= 1024, "chunk_length", s(chunk_length), "1..1024");
  require(history_length >= 0 && history_length <= 1024, "history_length", s(history_length),
          "0..1024");
  // Upper bounds keep every size a network is built from (sums and products of these) far from
  // int overflow, and a model file's config from describing an absurd network.
  require(hand_points >= 0 && hand_points <= kMaxPoints, "hand_points", s(hand_points), "0..65536");
  require(world_points >= 0 && world_points <= kMaxPoints, "world_points", s(world_points),
          "0..65536");
  require(action_dimension >= 0 && action_dimension <= kMaxDimension, "action_dimension",
          s(action_dimension), "0..1048576");
  require(observation_dimension >= 0 && observation_dimension <= kMaxDimension,
          "observation_dimension", s(observation_dimension), "0..1048576");
  require(hidden_width >= 1 && hidden_width <= 65536, "hidden_width", s(hidden_width), "1..65536");
  require(hidden_layers >= 1 && hidden_layers <= 64, "hidden_layers", s(hidden_layers), "1..64");
  require(time_embedding == 0 ||
              (time_embedding >= 2 && time_embedding % 2 == 0 && time_embedding <= 1024),
          "time_embedding", s(time_embedding), "0 (raw t) or an even number 2..1024");
  require(steps >= 0, "steps", s(steps), ">= 0");
  require(batch_size >= 1 && batch_size <= 1 << 20, "batch_size", s(batch_size), "1..1048576");
  require(learning_rate > 0.0 && learning_rate < 10.0, "learning_rate",
          format_number(learning_rate), "(0, 10)");
  require(weight_decay >= 0.0 && weight_decay < 1.0, "weight_decay", format_number(weight_decay),
          "[0, 1)");
  require(gradient_clip >= 0.0, "gradient_clip", format_number(gradient_clip), ">= 0 (0 disables)");
  require(ema_decay >= 0.0 && ema_decay < 1.0, "ema_decay", format_number(ema_decay),
          "[0, 1) (0 disables)");
  require(noise_scale >= 0.0 && noise_scale <= 10.0, "noise_scale", format_number(noise_scale),
          "[0, 10]");
  require(execute >= 1 && execute <= 1024, "execute", s(execute),
          "1..1024 (a rollout runs at most the K poses it has)");
  require(euler_steps >= 1 && euler_steps <= 10000, "euler_steps", s(euler_steps), "1..10000");
  require(ddpm_train_steps >= 2 && ddpm_train_steps <= 10000, "ddpm_train_steps",
          s(ddpm_train_steps), "2..10000");
  require(ddim_steps >= 1 && ddim_steps <= ddpm_train_steps, "ddim_steps", s(ddim_steps),
          "1..ddpm_train_steps (" + s(ddpm_train_steps) + ")");
  require(cvae_latent >= 1 && cvae_latent <= 4096, "cvae_latent", s(cvae_latent), "1..4096");
  require(std::isfinite(cvae_kl_weight) && cvae_kl_weight >= 0.0, "cvae_kl_weight",
          format_number(cvae_kl_weight), "a finite number >= 0");
  require(std::abs(c8_centre_x) <= 1e6, "c8_centre_x", format_number(c8_centre_x), "[-1e6, 1e6]");
  require(std::abs(c8_centre_y) <= 1e6, "c8_centre_y", format_number(c8_centre_y), "[-1e6, 1e6]");
  if (observation == ObservationKind::image) {
    require(head == HeadKind::flow, "head", to_string(head),
            "flow (the only head with an image encoder; or use observation key_points)");
    require(image_cameras == 1 || image_cameras == 2, "image_cameras", s(image_cameras),
            "1 or 2 (the hand camera and its mirror about the blade)");
    const int per_camera = image_channels / image_cameras;
    require(image_channels == 0 || (image_channels % image_cameras == 0 &&
                                    (per_camera == 1 || per_camera == 3 || per_camera == 4)),
            "image_channels", s(image_channels),
            "per camera 1 (depth), 3 (depth with normals) or 4 (rgbd), times image_cameras (" +
                s(image_cameras) + "), 0 before training");
    require(image_height >= 0 && image_height <= 4096, "image_height", s(image_height), "0..4096");
    require(image_width >= 0 && image_width <= 4096, "image_width", s(image_width), "0..4096");
    parse_encoder(encoder);  // names the bad entry
    require(std::isfinite(image_fov_deg) && image_fov_deg > 0.0 && image_fov_deg < 170.0,
            "image_fov_deg", format_number(image_fov_deg), "(0, 170)");
    require(observation_dimension == 0 || observation_dimension >= image_size(),
            "observation_dimension", s(observation_dimension),
            ">= the image's " + s(image_size()) + " values");
  }
}

std::vector<EncoderLayerSetting> parse_encoder(const std::string& text) {
  std::vector<EncoderLayerSetting> layers;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    std::string item = text.substr(begin, comma - begin);
    EncoderLayerSetting layer;
    std::string count = item;
    if (count.size() > 2 && count.ends_with("/1")) {
      count.resize(count.size() - 2);
      layer.stride = 1;
    }
    const auto [end, ec] =
        std::from_chars(count.data(), count.data() + count.size(), layer.channels);
    if (ec != std::errc() || end != count.data() + count.size() || layer.channels < 1 ||
        layer.channels > 256) {
      throw InvalidArgument("encoder '" + text + "': '" + item +
                            "' is not a channel count 1..256 (with /1 for stride 1); give the "
                            "out_channels of each layer comma-separated, e.g. 8,16/1");
    }
    layers.push_back(layer);
    begin = comma + 1;
  }
  if (layers.size() > 6) {
    throw InvalidArgument("encoder '" + text + "' has " + std::to_string(layers.size()) +
                          " layers: give 1 to 6");
  }
  return layers;
}

std::string PolicyConfig::to_text() const {
  std::string text;
  for (const Field& field : fields()) {
    if (!is_c8_planar(head) && field.key.starts_with("c8_")) continue;  // see config.hpp
    if (field.key == "task" && task == kTaskPeg2d) continue;            // absent reads as peg2d
    if (field.key == "ddpm_prediction" && head != HeadKind::ddpm) continue;  // see config.hpp
    if (observation == ObservationKind::key_points &&
        (field.key == "observation" || field.key.starts_with("image_") || field.key == "encoder"))
      continue;  // see config.hpp
    text += field.key + "=" + field.get(*this) + "\n";
  }
  return text;
}

PolicyConfig PolicyConfig::from_text(const std::string& text) {
  PolicyConfig config;
  bool has_ddpm_prediction = false;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos)
      throw InvalidArgument("policy config: line '" + line + "' is not key=value");
    const std::string key = line.substr(0, eq);
    if (key == "ddpm_prediction") has_ddpm_prediction = true;
    bool known = false;
    for (const Field& field : fields()) {
      if (field.key == key) {
        field.set(config, line.substr(eq + 1));
        known = true;
      }
    }
    if (!known) throw InvalidArgument("policy config: unknown key '" + key + "'");
  }
  // A ddpm model written before the setting existed predicted the noise.
  if (config.head == HeadKind::ddpm && !has_ddpm_prediction)
    config.ddpm_prediction = DdpmPrediction::epsilon;
  config.validate();
  return config;
}

}  // namespace handcentric::policy
