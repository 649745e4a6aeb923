// libopenable_dnn.so: OpenCV's DNN module reading and running ONNX networks for the ONNX
// descriptor (descriptors/onnx.h). A module, loaded on first use (OpenABLE/base/module_loader.h),
// so that runs without a model do not load OpenCV's DNN library and its protobuf.
#include <memory>
#include <opencv2/dnn.hpp>
#include <string>

#include "descriptors/onnx.h"

namespace {

class DnnNetwork : public openable::OnnxNetwork {
 public:
  explicit DnnNetwork(cv::dnn::Net net) : net_(std::move(net)) {}
  cv::Mat Forward(const cv::Mat& input) override {
    net_.setInput(input);
    return net_.forward().clone();
  }

 private:
  cv::dnn::Net net_;
};

}  // namespace

// Reads the ONNX network at `path` (cv::dnn::readNetFromONNX, the default backend and target:
// OpenCV's own CPU code). Throws cv::Exception when OpenCV cannot import it.
extern "C" void openable_dnn_load(const std::string& path,
                                  std::unique_ptr<openable::OnnxNetwork>& network) {
  network = std::make_unique<DnnNetwork>(cv::dnn::readNetFromONNX(path));
}
