#include "camproj/library_logging.h"

#include <glog/logging.h>
#include <opencv2/core/utils/logger.hpp>

namespace camproj {

void SetLibraryLogging(bool verbose) {
  FLAGS_minloglevel = verbose ? google::GLOG_WARNING : google::GLOG_FATAL;
  cv::utils::logging::setLogLevel(verbose ? cv::utils::logging::LOG_LEVEL_WARNING
                                          : cv::utils::logging::LOG_LEVEL_SILENT);
}

}  // namespace camproj
