#include "handcentric/props/view.hpp"

namespace handcentric::props {

std::string to_string(View view) {
  return view == View::eye_in_hand ? "eye_in_hand" : "third_person";
}

}  // namespace handcentric::props
