/// @file field_replacement.h
/// @brief Writing a field file (a header NAME.json and its channel files) so that, at every
/// instant, whatever fails or kills the writer, NAME.json describes either the old field whole
/// or the new one whole (docs/field-format.md, "Replacing a field").
///
/// The header is the commit point. The new channel files are written under names that no
/// file and no existing header uses: NAME.<channel>.raw when free, else
/// NAME.<channel>.<tag>.raw with a tag unique to this write. The old header, and the old
/// channel files it names, stay untouched until the new header has been renamed over it in
/// one atomic step; only then are the old channel files removed. Readers need no change: a
/// header names its channel files.
///
///   1. FieldReplacement(header, channels, overwrite): every target is checked (before any
///      sampling); the channel files' final names are chosen.
///   2. The writer fills each channel file (any way: a temporary it renames with place(), or
///      write_file_atomically to the final name and placed()); each is fsynced.
///   3. commit(field): the header, atomically (the commit point), then the old field's
///      channel files that the new header does not name are removed.
/// Destroyed without commit(), it removes the channel files it placed: the old field stays.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "harness/io/field_file.h"

namespace sdf {

class FieldReplacement {
public:
    /// `channels` as field_channel_files() lays them out (NAME.<channel>.raw). Throws,
    /// naming the file, when the header's folder is missing or not writable, or when a target
    /// exists and `overwrite` is Forbid.
    FieldReplacement(std::string header_path, std::vector<FieldChannelFile> channels, Overwrite overwrite);
    ~FieldReplacement();
    FieldReplacement(const FieldReplacement&) = delete;
    FieldReplacement& operator=(const FieldReplacement&) = delete;

    /// The channel files with their final paths (not used by any file before this write).
    const std::vector<FieldChannelFile>& channels() const { return channels_; }
    /// Renames the complete, fsynced file `staged` to channel `i`'s final path (never
    /// replacing a file).
    void place(size_t i, const std::string& staged);
    /// Records that channel `i`'s final path was written by the caller.
    void placed(size_t i);
    /// Writes the header of `field` over the old one in one atomic step, then removes the old
    /// field's channel files that the new header does not name. Every channel must be placed.
    void commit(const SampledField& field);
    /// The same for a header written by `write_header` (atomically, at the header's path,
    /// naming the final channel paths it is given): the sparse band's file
    /// (sparse_field_file.h) commits this way.
    void commit_with(const std::function<void(const std::vector<FieldChannelFile>&)>& write_header);

private:
    std::string header_;
    std::vector<FieldChannelFile> channels_;
    Overwrite overwrite_;
    std::vector<bool> placed_;
    bool committed_ = false;
};

/// Whether `file` (a name in the header's folder) is one of the channel file names that
/// FieldReplacement gives the field of header `header_path`: NAME.<channel>.raw or
/// NAME.<channel>.<tag>.raw. Only such files are ever removed by a replacement.
bool is_field_channel_name(const std::string& header_path, const std::string& file);

}  // namespace sdf
