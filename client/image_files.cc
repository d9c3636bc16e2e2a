#include "client/image_files.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace tod::client {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool IsImage(const fs::path& path) {
  const std::string ext = LowerExtension(path);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

}  // namespace

Result<std::vector<std::string>> CollectImages(const std::vector<std::string>& paths) {
  std::vector<std::string> images;
  for (const std::string& arg : paths) {
    std::error_code error;
    const fs::path path(arg);
    if (fs::is_directory(path, error)) {
      std::vector<std::string> found;
      for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
        if (entry.is_regular_file() && IsImage(entry.path())) found.push_back(entry.path());
      }
      if (error) return Status::NotFound(arg + ": cannot list folder: " + error.message());
      if (found.empty()) return Status::NotFound(arg + ": folder holds no .png/.jpg/.jpeg file");
      std::sort(found.begin(), found.end());
      images.insert(images.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(path, error)) {
      images.push_back(arg);
    } else {
      return Status::NotFound(arg + ": no such image file or folder");
    }
  }
  return images;
}

Result<std::string> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return Status::DataLoss(path + ": read error");
  return bytes;
}

Status WriteFileBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Status::NotFound(path + ": cannot create");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Status::DataLoss(path + ": write error");
  return Status::Ok();
}

std::string ContentTypeFor(const std::string& path) {
  const std::string ext = LowerExtension(path);
  return ext == ".jpg" || ext == ".jpeg" ? "image/jpeg" : "image/png";
}

}  // namespace tod::client
