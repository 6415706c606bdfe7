#ifndef FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_
#define FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_

#include <opencv2/core.hpp>

namespace fovea {

// A saliency map is a CV_32FC1 cv::Mat the size of the frame with values in
// [0, 1]; 0 where nothing is salient or there is no data.

// Linear normalisation (thesis eq. 2.37): divides by the maximum so the map
// spans [0, 1] (the minimum of a saliency map is 0 by construction: the
// table). A map that is all zero stays zero. In place.
void NormalizeLinear(cv::Mat& map);

}  // namespace fovea

#endif  // FOVEA_CORE_SALIENCY_SALIENCY_MAP_H_
