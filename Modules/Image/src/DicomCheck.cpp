// DICOM files: the walk of their elements made before GDCM reads them (FileChecks.h).
#include "FileChecks.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <set>

#include "dynsub/Error.h"

namespace dynsub::filechecks {
namespace fs = std::filesystem;

namespace {

// GDCM, as Debian builds it, aborts the process (a failed assertion) on a
// file cut short before its pixel data. So the elements of each DICOM file are
// walked first, and each must fit in the file: the meta header (explicit VR,
// little endian), then a data set in either uncompressed little-endian
// transfer syntax (explicit or implicit VR), sequences and items of undefined
// length included, and encapsulated pixel data fragment by fragment. A data
// set in another transfer syntax (deflated, big endian) is left to GDCM:
// run() says whether the whole file was walked.
class DicomWalk {
 public:
  explicit DicomWalk(const fs::path& file) : file_(file), size_(fs::file_size(file)), in_(file, std::ios::binary) {}

  bool run() {
    std::uintmax_t at = 132;
    // The meta header: explicit VR little endian, group 0002, first; its
    // length, when given (0002,0000), must be there too.
    if (group(at) == 0x0002 && number(at + 2, 2) == 0x0000 && 144 + number(at + 8, 4) > size_)
      fail("the meta header needs " + std::to_string(number(at + 8, 4)) + " bytes, the file has " +
           std::to_string(size_ - std::min<std::uintmax_t>(size_, 144)));
    while (at < size_ && group(at) == 0x0002) at = element(at);
    if (syntax_.empty()) fail("the meta header ends before its transfer syntax");
    if (at >= size_) fail("nothing follows the meta header");
    if (syntax_ == "1.2.840.10008.1.2") {
      explicitVr_ = false;
    } else if (syntax_ != "1.2.840.10008.1.2.1" && !isEncapsulated()) {
      return false;  // deflated or big endian: GDCM's alone
    }
    elements(at, false);
    return true;
  }

 private:
  static constexpr std::uint32_t kUndefined = 0xFFFFFFFFu;

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(file_.string(), "a truncated DICOM file: " + what);
  }
  // Little-endian unsigned of n bytes at `at`; fails beyond the end.
  std::uint32_t number(std::uintmax_t at, int n) {
    if (at + n > size_) fail("an element is cut short at byte " + std::to_string(at));
    unsigned char bytes[4] = {};
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(reinterpret_cast<char*>(bytes), n);
    std::uint32_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | bytes[i];
    return v;
  }
  unsigned group(std::uintmax_t at) { return number(at, 2); }
  // JPEG, JPEG-LS, JPEG 2000, RLE: explicit VR little endian with encapsulated pixel data.
  bool isEncapsulated() const {
    return syntax_.rfind("1.2.840.10008.1.2.4.", 0) == 0 || syntax_ == "1.2.840.10008.1.2.5";
  }

  // Elements from `at` to the end of the file or, in an item of undefined
  // length, to its delimiter; returns the position after them.
  std::uintmax_t elements(std::uintmax_t at, bool inItem) {
    while (at < size_) {
      if (group(at) == 0xFFFE) {
        if (inItem && number(at + 2, 2) == 0xE00D) return at + 8;
        fail("a stray item delimiter at byte " + std::to_string(at));
      }
      at = element(at);
    }
    if (inItem) fail("an item of undefined length has no end");
    return at;
  }

  // One element at `at`; returns the position after it.
  std::uintmax_t element(std::uintmax_t at) {
    const unsigned tagGroup = group(at), tagElement = number(at + 2, 2);
    std::uintmax_t header = 8;
    std::uint32_t length = 0;
    const bool explicitVr = explicitVr_ || tagGroup == 0x0002;
    if (explicitVr) {
      const std::uint32_t vr = number(at + 4, 2);
      const std::string name{static_cast<char>(vr & 0xFF), static_cast<char>(vr >> 8)};
      static const std::set<std::string> longLength = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                       "SV", "UC", "UN", "UR", "UT", "UV"};
      if (longLength.count(name)) {
        length = number(at + 8, 4);
        header = 12;
      } else {
        length = number(at + 6, 2);
      }
    } else {
      length = number(at + 4, 4);
    }
    if (length == kUndefined) return sequence(at + header);  // a sequence, or encapsulated pixel data
    if (at + header + length > size_) {
      char name[16];
      std::snprintf(name, sizeof name, "(%04x,%04x)", tagGroup, tagElement);
      fail(std::string("element ") + name + " needs " + std::to_string(length) + " bytes, the file has " +
           std::to_string(size_ - at - header));
    }
    if (tagGroup == 0x0002 && tagElement == 0x0010) {  // the transfer syntax UID
      std::string value(length, '\0');
      in_.seekg(static_cast<std::streamoff>(at + header));
      in_.read(value.data(), static_cast<std::streamsize>(length));
      while (!value.empty() && (value.back() == '\0' || value.back() == ' ')) value.pop_back();
      syntax_ = value;
    }
    return at + header + length;
  }

  // Items (or pixel data fragments) up to the sequence delimiter.
  std::uintmax_t sequence(std::uintmax_t at) {
    while (true) {
      if (group(at) != 0xFFFE) fail("a sequence without its delimiter at byte " + std::to_string(at));
      const unsigned tagElement = number(at + 2, 2);
      const std::uint32_t length = number(at + 4, 4);
      if (tagElement == 0xE0DD) return at + 8;
      if (tagElement != 0xE000) fail("a sequence holds something other than items at byte " + std::to_string(at));
      if (length == kUndefined) {
        at = elements(at + 8, true);
      } else {
        if (at + 8 + length > size_)
          fail("an item needs " + std::to_string(length) + " bytes, the file has " + std::to_string(size_ - at - 8));
        at += 8 + length;
      }
    }
  }

  fs::path file_;
  std::uintmax_t size_;
  std::ifstream in_;
  bool explicitVr_ = true;
  std::string syntax_;
};

}  // namespace

bool isDicomFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  in.seekg(128);
  return in.read(magic, 4) && std::string(magic, 4) == "DICM";
}

bool walkDicomFile(const fs::path& file) { return DicomWalk(file).run(); }

}  // namespace dynsub::filechecks
