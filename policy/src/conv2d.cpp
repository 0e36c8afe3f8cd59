#include "handcentric/policy/conv2d.hpp"

#include <cstdint>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::policy {

namespace {

void require_at_least(const std::string& what, long value, long least, const std::string& fix) {
  if (value < least) {
    throw InvalidArgument("Conv2d " + what + " is " + std::to_string(value) + ": " + fix);
  }
}

}  // namespace

Conv2d::Conv2d(ImageShape input, int out_channels, int kernel, int stride, int padding)
    : input_(input), kernel_(kernel), stride_(stride), padding_(padding) {
  require_at_least("input channels", input.channels, 1, "an image has at least one channel");
  require_at_least("input height", input.height, 1, "an image is at least 1 x 1");
  require_at_least("input width", input.width, 1, "an image is at least 1 x 1");
  require_at_least("out_channels", out_channels, 1, "a layer has at least one filter");
  require_at_least("kernel", kernel, 1, "use 1 or more (3 is usual)");
  require_at_least("stride", stride, 1, "use 1, or 2 to halve the image");
  require_at_least("padding", padding, 0, "use 0 or more (kernel / 2 keeps the size at stride 1)");
  if (padding >= kernel) {
    throw InvalidArgument("Conv2d padding is " + std::to_string(padding) + " with a kernel of " +
                          std::to_string(kernel) +
                          ": a window would see only padding; use a padding < kernel");
  }
  const long height = input.height + 2L * padding, width = input.width + 2L * padding;
  if (kernel > height || kernel > width) {
    throw InvalidArgument("Conv2d kernel is " + std::to_string(kernel) +
                          " but the padded input is " + std::to_string(height) + " x " +
                          std::to_string(width) +
                          ": use a smaller kernel or fewer stride-2 layers before this one");
  }
  output_ = {out_channels, static_cast<int>((height - kernel) / stride + 1),
             static_cast<int>((width - kernel) / stride + 1)};
  // The products index a patch matrix and an image with int dimensions (kernels/gemm.hpp).
  const long patch = static_cast<long>(kernel) * kernel * input.channels;
  const long per_image = patch * output_.height * output_.width;
  const long limit = std::int64_t{1} << 31;
  if (static_cast<long>(input.channels) * input.height * input.width >= limit ||
      per_image >= limit || static_cast<long>(out_channels) * (patch + 1) >= limit) {
    throw InvalidArgument("Conv2d of " + std::to_string(input.channels) + " x " +
                          std::to_string(input.height) + " x " + std::to_string(input.width) +
                          " -> " + std::to_string(out_channels) + " channels, kernel " +
                          std::to_string(kernel) +
                          " has more than 2^31 entries per image: use a smaller image or layer");
  }
}

}  // namespace handcentric::policy
