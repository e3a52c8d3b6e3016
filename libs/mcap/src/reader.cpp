#include "avs/mcap/reader.hpp"

#include "decoder.hpp"

namespace avs::mcap {

struct Reader::Impl {
  std::unique_ptr<detail::Decoder> decoder;
  Footer footer;
  Summary summary;
  bool summary_attempted = false;
  bool has_summary = false;
  bool summary_from_file = false;
  Status summary_status;
};

Reader::Reader() = default;
Reader::~Reader() = default;
Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;

Status Reader::open(const std::filesystem::path& path, const ReaderOptions& options) {
  std::unique_ptr<detail::Source> source;
  if (Status s = detail::open_file_source(path, source); !s.ok()) return s;
  auto impl = std::make_unique<Impl>();
  impl->decoder = std::make_unique<detail::Decoder>(std::move(source), options);
  if (Status s = impl->decoder->open(); !s.ok()) {
    return Status(s.code(), path.string() + ": " + s.message());
  }
  impl_ = std::move(impl);
  return {};
}

Status Reader::open_memory(std::span<const std::byte> bytes, const ReaderOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->decoder = std::make_unique<detail::Decoder>(detail::make_memory_source(bytes), options);
  if (Status s = impl->decoder->open(); !s.ok()) return s;
  impl_ = std::move(impl);
  return {};
}

const Header& Reader::header() const {
  static const Header empty;
  return impl_ ? impl_->decoder->header() : empty;
}

std::uint64_t Reader::file_size() const {
  return impl_ ? impl_->decoder->source().size() : 0;
}

Status Reader::read_summary() {
  if (!impl_) return Status(StatusCode::invalid_argument, "read_summary: reader is not open");
  Impl& m = *impl_;
  if (!m.summary_attempted) {
    m.summary_attempted = true;
    m.summary_status = m.decoder->read_summary(m.footer, m.summary, m.has_summary);
    m.summary_from_file = m.has_summary;
    if (m.summary_status.ok() && !m.has_summary) {
      m.summary_status = Status(StatusCode::unsupported, "the Footer says the file has no summary");
    }
  }
  return m.summary_status;
}

bool Reader::has_summary() const {
  return impl_ && impl_->has_summary;
}

const Summary& Reader::summary() const {
  static const Summary empty;
  return impl_ ? impl_->summary : empty;
}

const Footer& Reader::footer() const {
  static const Footer empty;
  return impl_ ? impl_->footer : empty;
}

Status Reader::scan(ScanResult& result, bool allow_truncated, const MessageCallback& on_message) {
  if (!impl_) return Status(StatusCode::invalid_argument, "scan: reader is not open");
  Status s = impl_->decoder->scan(result, allow_truncated, on_message, {});
  if (s.ok() && !impl_->has_summary) {
    impl_->summary = result.summary;
    impl_->has_summary = true;
    impl_->summary_from_file = false;
  }
  return s;
}

Status Reader::read_metadata(const MetadataIndex& index, Metadata& out) {
  if (!impl_) return Status(StatusCode::invalid_argument, "read_metadata: reader is not open");
  return impl_->decoder->read_metadata(index, out);
}

Status Reader::read_messages(const MessageCallback& on_message, const ReadOptions& options,
                             ReadReport* report) {
  if (!impl_) return Status(StatusCode::invalid_argument, "read_messages: reader is not open");
  Impl& m = *impl_;
  ReadReport local;
  ReadReport& out = report != nullptr ? *report : local;
  out = ReadReport{};
  if (!m.summary_attempted) (void)read_summary();
  bool use_index = false;
  std::uint64_t data_limit = m.decoder->source().size();
  if (m.summary_from_file) {
    const bool has_messages = m.summary.statistics && m.summary.statistics->message_count > 0;
    if (!m.summary.chunk_indexes.empty() || !has_messages) {
      use_index = true;
      out.used_summary = true;
      data_limit = m.footer.summary_start;
    } else {
      out.summary_problem = "summary has no Chunk Indexes";
    }
  } else {
    out.summary_problem = m.summary_status.message();
  }
  if (!use_index) {
    if (!options.allow_fallback_scan) {
      return Status(m.summary_status.ok() ? StatusCode::unsupported : m.summary_status.code(),
                    "cannot read in log-time order without a summary: " + out.summary_problem);
    }
    out.used_linear_scan = true;
    ScanResult scanned;
    if (Status s = m.decoder->scan(scanned, options.allow_truncated, {}, {}); !s.ok()) return s;
    out.skipped_chunks = scanned.skipped_chunks;
    out.truncated = scanned.truncated;
    out.truncated_at = scanned.truncated_at;
    out.truncation_detail = scanned.truncation_detail;
    if (scanned.loose_message_count > 0) {
      // Messages outside chunks cannot be merged through indexes: deliver in file order.
      ScanResult again;
      auto filtered = [&](const MessageView& view) {
        if (view.log_time < options.start_time || view.log_time > options.end_time) return true;
        if (!options.topics.empty() && options.topics.count(view.channel->topic) == 0) {
          return true;
        }
        ++out.messages_delivered;
        return on_message(view);
      };
      return m.decoder->scan(again, options.allow_truncated, filtered, {});
    }
    m.summary = std::move(scanned.summary);
    m.has_summary = true;
    data_limit = scanned.last_complete_offset;
  }
  return m.decoder->read_indexed(m.summary, data_limit, m.summary_from_file, options, on_message,
                                 out.messages_delivered, out.skipped_chunks);
}

}  // namespace avs::mcap
