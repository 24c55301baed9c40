#pragma once
/** \file
 * What a LAS file holds besides its points' fields: version, point format, scale and offset, the
 * variable-length records (projection, metadata, Extra Bytes) and the header's identification.
 * readMeshFile fills one for a .las file (MeshFile::las); handed back to saveMesh
 * (MeshWriteOptions::las), a .las output keeps all of it, so that unchanged points and every VLR
 * round-trip bit for bit. See docs/las.md for the fields a LAS point becomes in the cloud.
 */
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace pcl_ddg {

/** A VLR (data up to 65,535 bytes) or an EVLR (LAS 1.4, 64-bit length), kept as its bytes. */
struct LasVariableLengthRecord {
  std::uint16_t reserved = 0;
  std::string user_id;  ///< the 16 bytes as stored (NUL padded)
  std::uint16_t record_id = 0;
  std::string description;  ///< the 32 bytes as stored (NUL padded)
  std::string data;

  /** user_id up to its first NUL ("LASF_Projection"). */
  std::string userId() const;
  /** description up to its first NUL. */
  std::string descriptionText() const;
};

/** One dimension of an Extra Bytes VLR (user "LASF_Spec", record 4): the 192-byte descriptor as
 *  stored, and the cloud field it was read into. */
struct LasExtraBytesDimension {
  std::string field;       ///< the cloud's field name
  std::string descriptor;  ///< 192 bytes: data type, options, name, no_data/min/max, scale, offset
};

struct LasLayout {
  std::uint8_t version_major = 1;
  std::uint8_t version_minor = 4;
  std::uint8_t point_format = 6;    ///< 0-10
  std::uint16_t record_length = 0;  ///< of the file read (0 for a new file)
  std::uint16_t file_source_id = 0;
  std::uint16_t global_encoding = 0;
  std::string project_id = std::string(16, '\0');  ///< GUID, 16 bytes as stored
  std::string system_identifier;                   ///< 32 bytes as stored
  std::string generating_software;                 ///< 32 bytes as stored
  std::uint16_t creation_day = 0, creation_year = 0;
  Eigen::Vector3d scale = Eigen::Vector3d::Constant(0.001);
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /** The header's own bounds as read (pcl_ddg_info compares them with the records'); a written
   *  file's are the records' again. */
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();
  std::uint64_t point_count = 0;  ///< as read
  /** Every VLR in file order, the Extra Bytes one included (rewritten when the fields change). */
  std::vector<LasVariableLengthRecord> vlrs;
  std::vector<LasVariableLengthRecord> evlrs;
  /** The waveform data packets' EVLR (index into evlrs), -1 if none is in the file. */
  int waveform_evlr = -1;
  std::string header_extra;  ///< bytes of the header beyond its version's size
  std::string after_vlrs;    ///< bytes between the last VLR and the first point (1.0's 0xDDCC)
  /** The Extra Bytes VLR's dimensions, in record order. */
  std::vector<LasExtraBytesDimension> extra_bytes;
  /** Bytes at the end of each record that no Extra Bytes descriptor describes (field
   *  las_undocumented_bytes). */
  std::uint32_t undocumented_bytes = 0;
};

/** The bytes of one record of a point data record format (0-10): 20, 28, 26, 34, 57, 63, 30, 36,
 *  38, 59, 67; 0 for any other format. */
std::uint16_t lasPointFormatSize(int point_format);

/** Whether a LAS file's first bytes (head) mark it as compressed (LAZ): the two high bits of the
 *  point format byte (104) set (readMeshFile and CloudPieceReader then decompress it). */
bool lasIsCompressed(std::string_view head);

/** Whether LAZ holds records of this point format: 0-3 and 6-8, not the waveform formats 4, 5,
 *  9 and 10 (a .laz output of them is refused). */
bool lazCompressible(int point_format);

/** The field holding a record's bytes that no Extra Bytes descriptor describes (UINT8, count n). */
inline constexpr const char* kLasUndocumentedBytesField = "las_undocumented_bytes";

}  // namespace pcl_ddg
