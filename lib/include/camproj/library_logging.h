// The log output of the libraries camproj calls: glog (through Ceres) and OpenCV.
#ifndef CAMPROJ_LIBRARY_LOGGING_H_
#define CAMPROJ_LIBRARY_LOGGING_H_

namespace camproj {

// verbose = false: glog prints only FATAL messages and OpenCV nothing, so a program's stderr holds
// its own messages only (camproj's default); true: both libraries' defaults (glog WARNING and
// above, OpenCV's warnings), for `camproj --verbose`. Process-wide; call it before other threads
// start.
void SetLibraryLogging(bool verbose);

}  // namespace camproj

#endif  // CAMPROJ_LIBRARY_LOGGING_H_
