#pragma once
/// The error of every mesh file reader and writer other than PLY's own.

#include <stdexcept>

namespace featsense::viewer_export {

/// A mesh file that cannot be read or written; the message names the file and what is wrong.
class MeshFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace featsense::viewer_export
