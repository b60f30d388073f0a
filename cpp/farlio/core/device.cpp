#include "farlio/core/device.hpp"

#include <stdexcept>

namespace farlio {

const char* device_name(Device d) {
  switch (d) {
    case Device::Cpu: return "cpu";
    case Device::Cuda: return "cuda";
    case Device::Auto: break;
  }
  return "auto";
}

Device parse_device(const std::string& text, const std::string& what) {
  for (const Device d : {Device::Cpu, Device::Cuda, Device::Auto}) {
    if (text == device_name(d)) return d;
  }
  throw std::invalid_argument(what + ": expected auto, cpu or cuda, got '" + text + "'");
}

}  // namespace farlio
