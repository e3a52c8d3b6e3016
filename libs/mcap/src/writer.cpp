#include "avs/mcap/writer.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "checksum.hpp"
#include "compression.hpp"
#include "file_io.hpp"
#include "serialize.hpp"
#include "tail_writer.hpp"

namespace avs::mcap {

using detail::ByteBuffer;

namespace {

/// A unit of work for the output stage: a chunk being filled, or a ready Metadata record.
struct Job {
  bool is_metadata = false;
  ByteBuffer records;  // chunk: uncompressed records; metadata: the whole record
  std::string metadata_name;
  detail::ChunkMessageIndex index;
  Timestamp start = 0;
  Timestamp end = 0;
  std::uint64_t message_count = 0;

  void reset() {
    is_metadata = false;
    records.clear();
    metadata_name.clear();
    for (auto& [id, entries] : index) entries.clear();  // keep capacity
    start = end = 0;
    message_count = 0;
  }
};

constexpr std::size_t kMessageRecordHeader = 1 + 8 + 2 + 4 + 8 + 8;

}  // namespace

struct Writer::Impl {
  WriterOptions options;
  detail::OutputFile file;
  std::unique_ptr<detail::Compressor> compressor;
  ByteBuffer compressed;  // output stage only
  ByteBuffer scratch;     // output stage only
  std::unique_ptr<Job> current;

  // Caller-thread state.
  std::map<SchemaId, Schema> schemas;
  std::map<ChannelId, Channel> channels;
  Statistics statistics;
  std::uint64_t message_bytes = 0;

  // Output-stage state (read by the caller only after the worker is joined).
  // The summary's Chunk Index records, serialized as each chunk is written: a recording keeps
  // one per chunk until close(), so they are kept as the ~117 bytes they take in the file
  // rather than as ChunkIndex structs with a map (~480 bytes with four channels;
  // tests/mcap/mcap_writer_memory_test.cpp).
  ByteBuffer chunk_index_records;
  std::uint32_t chunk_index_count = 0;
  std::vector<MetadataIndex> metadata_indexes;
  std::atomic<std::uint64_t> chunks_written{0};
  std::atomic<std::uint64_t> bytes_written{0};
  std::atomic<std::uint64_t> messages_in_file{0};
  mutable std::mutex in_file_mutex;
  std::map<ChannelId, std::uint64_t> channel_messages_in_file;  // guarded by in_file_mutex

  // Background stage.
  std::thread worker;
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::unique_ptr<Job>> queue;
  std::vector<std::unique_ptr<Job>> pool;
  std::size_t in_flight = 0;
  bool stopping = false;
  std::atomic<bool> failed{false};
  Status output_error;  // guarded by mutex

  ~Impl() { stop_worker(); }

  std::unique_ptr<Job> take_job() {
    std::unique_ptr<Job> job;
    {
      std::lock_guard lock(mutex);
      if (!pool.empty()) {
        job = std::move(pool.back());
        pool.pop_back();
      }
    }
    if (!job) {
      job = std::make_unique<Job>();
      job->records.reserve(options.chunk_size_bytes + options.chunk_size_bytes / 8 + 4096);
    }
    job->reset();
    return job;
  }

  Status output_status() {
    if (!failed.load()) return {};
    std::lock_guard lock(mutex);
    return output_error;
  }

  void record_failure(Status status) {
    std::lock_guard lock(mutex);
    if (output_error.ok()) output_error = std::move(status);
    failed.store(true);
  }

  // ---- output stage: compress + write (worker thread, or caller when synchronous) ----
  Status write_chunk(Job& job) {
    const std::uint64_t chunk_start = file.position();
    const std::uint32_t crc = options.chunk_crc ? detail::crc32_update(0, job.records.span()) : 0;
    std::span<const std::byte> payload = job.records.span();
    if (options.compression != Compression::none) {
      if (Status s = compressor->compress(job.records.span(), compressed); !s.ok()) return s;
      payload = compressed.span();
    }
    const std::string_view compression = compression_field(options.compression);
    scratch.clear();
    detail::put_chunk_header(scratch, job.start, job.end, job.records.size(), crc, compression,
                             payload.size());
    if (Status s = file.write(scratch); !s.ok()) return s;
    // Uncompressed: the chunk CRC is also the CRC of the payload bytes in the file.
    const bool known_crc = options.chunk_crc && options.compression == Compression::none;
    if (Status s = known_crc ? file.write(payload, crc) : file.write(payload); !s.ok()) return s;

    ChunkIndex index;
    index.message_start_time = job.start;
    index.message_end_time = job.end;
    index.chunk_start_offset = chunk_start;
    index.chunk_length = file.position() - chunk_start;
    index.compression = std::string(compression);
    index.compressed_size = payload.size();
    index.uncompressed_size = job.records.size();
    scratch.clear();
    detail::put_message_index_records(scratch, file.position(), job.index,
                                      index.message_index_offsets);
    index.message_index_length = scratch.size();
    if (Status s = file.write(scratch); !s.ok()) return s;
    // Every finished chunk reaches the kernel now: a killed recorder loses at most the chunk
    // being filled (docs/bag.md, repair), never staged records of earlier ones.
    if (Status s = file.flush(); !s.ok()) return s;
    detail::put_chunk_index_record(chunk_index_records, index);
    ++chunk_index_count;
    chunks_written.fetch_add(1);
    messages_in_file.fetch_add(job.message_count);
    {
      std::lock_guard lock(in_file_mutex);
      for (const auto& [channel, entries] : job.index) {
        channel_messages_in_file[channel] += entries.size();
      }
    }
    bytes_written.store(file.position());
    return {};
  }

  Status write_job(Job& job) {
    if (!job.is_metadata) return write_chunk(job);
    MetadataIndex index{file.position(), job.records.size(), job.metadata_name};
    if (Status s = file.write(job.records); !s.ok()) return s;
    metadata_indexes.push_back(std::move(index));
    bytes_written.store(file.position());
    return {};
  }

  void worker_loop() {
    for (;;) {
      std::unique_ptr<Job> job;
      {
        std::unique_lock lock(mutex);
        changed.wait(lock, [&] { return stopping || !queue.empty(); });
        if (queue.empty()) return;
        job = std::move(queue.front());
        queue.pop_front();
      }
      if (!failed.load()) {
        if (Status s = write_job(*job); !s.ok()) record_failure(std::move(s));
      }
      {
        std::lock_guard lock(mutex);
        pool.push_back(std::move(job));
        --in_flight;
      }
      changed.notify_all();
    }
  }

  void stop_worker() {
    if (!worker.joinable()) return;
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    changed.notify_all();
    worker.join();
  }

  /// Hands a finished job to the output stage (blocks while max_chunks_in_flight are queued).
  Status submit(std::unique_ptr<Job> job) {
    if (!options.background_compression) {
      Status s = write_job(*job);
      job->reset();
      std::lock_guard lock(mutex);
      pool.push_back(std::move(job));
      return s;
    }
    {
      std::unique_lock lock(mutex);
      changed.wait(lock, [&] { return in_flight < options.max_chunks_in_flight; });
      ++in_flight;
      queue.push_back(std::move(job));
    }
    changed.notify_all();
    return output_status();
  }

  Status finish_chunk() {
    if (current->records.empty()) return {};
    std::unique_ptr<Job> done = std::move(current);
    current = take_job();
    return submit(std::move(done));
  }
};

Writer::Writer() = default;
Writer::~Writer() {
  if (is_open()) (void)close();
}
Writer::Writer(Writer&&) noexcept = default;
Writer& Writer::operator=(Writer&& other) noexcept {
  if (this != &other) {
    if (is_open()) (void)close();  // an open file is finished, not abandoned
    impl_ = std::move(other.impl_);
  }
  return *this;
}

bool Writer::is_open() const {
  return impl_ != nullptr && impl_->file.is_open();
}

Status Writer::open(const std::filesystem::path& path, const WriterOptions& options) {
  if (is_open()) return Status(StatusCode::invalid_argument, "writer already open");
  if (options.chunk_size_bytes == 0 || options.max_chunks_in_flight == 0) {
    return Status(StatusCode::invalid_argument,
                  "chunk_size_bytes and max_chunks_in_flight must be positive");
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  if (Status s = impl->file.open(path); !s.ok()) return s;
  impl->file.set_crc_enabled(options.data_section_crc);
  if (options.compression != Compression::none) {
    impl->compressor =
        std::make_unique<detail::Compressor>(options.compression, options.compression_level);
  }
  ByteBuffer head;
  head.append(kMagic, kMagicSize);
  std::size_t at = detail::begin_record(head, Opcode::header);
  detail::put_string(head, options.profile);
  detail::put_string(head, options.library);
  detail::end_record(head, at);
  if (Status s = impl->file.write(head); !s.ok()) return s;
  // The magic and the Header reach the kernel at once: a recorder killed before its first chunk
  // leaves a file that `bag info` reads and `bag repair` completes, not an empty one.
  if (Status s = impl->file.flush(); !s.ok()) return s;
  impl->current = impl->take_job();
  if (options.background_compression) {
    impl->worker = std::thread([raw = impl.get()] { raw->worker_loop(); });
  }
  impl_ = std::move(impl);
  return {};
}

Status Writer::add_schema(std::string_view name, std::string_view encoding, std::string_view data,
                          SchemaId& id_out) {
  if (!is_open()) return Status(StatusCode::invalid_argument, "add_schema: writer is not open");
  Impl& m = *impl_;
  if (m.options.profile == "ros2" && encoding != "ros2msg" && encoding != "ros2idl") {
    return Status(StatusCode::invalid_argument,
                  "add_schema " + std::string(name) +
                      ": the ros2 profile needs schema encoding ros2msg or ros2idl, got \"" +
                      std::string(encoding) + "\"");
  }
  for (const auto& [id, schema] : m.schemas) {
    if (schema.name == name && schema.encoding == encoding && schema.data == data) {
      id_out = id;
      return {};
    }
  }
  if (m.schemas.size() >= 0xFFFF) {
    return Status(StatusCode::invalid_argument, "add_schema: 65535 schemas already");
  }
  Schema schema{static_cast<SchemaId>(m.schemas.size() + 1), std::string(name),
                std::string(encoding), std::string(data)};
  detail::put_schema_record(m.current->records, schema);
  id_out = schema.id;
  m.schemas.emplace(schema.id, std::move(schema));
  return {};
}

Status Writer::add_channel(std::string_view topic, std::string_view message_encoding,
                           SchemaId schema_id, const KeyValueMap& metadata, ChannelId& id_out) {
  if (!is_open()) return Status(StatusCode::invalid_argument, "add_channel: writer is not open");
  Impl& m = *impl_;
  const std::string where = "add_channel " + std::string(topic) + ": ";
  if (schema_id != 0 && m.schemas.count(schema_id) == 0) {
    return Status(StatusCode::invalid_argument,
                  where + "unknown schema id " + std::to_string(schema_id));
  }
  if (m.options.profile == "ros2") {
    if (message_encoding != "cdr") {
      return Status(StatusCode::invalid_argument, where +
                                                      "the ros2 profile needs message "
                                                      "encoding cdr, got \"" +
                                                      std::string(message_encoding) + "\"");
    }
    if (metadata.count("offered_qos_profiles") == 0) {
      return Status(StatusCode::invalid_argument,
                    where + "the ros2 profile needs metadata offered_qos_profiles");
    }
    if (schema_id == 0) {
      return Status(StatusCode::invalid_argument, where + "the ros2 profile needs a schema");
    }
  }
  for (const auto& [id, channel] : m.channels) {
    if (channel.topic == topic && channel.message_encoding == message_encoding &&
        channel.schema_id == schema_id && channel.metadata == metadata) {
      id_out = id;
      return {};
    }
  }
  if (m.channels.size() >= 0xFFFF) {
    return Status(StatusCode::invalid_argument, where + "65535 channels already");
  }
  Channel channel{static_cast<ChannelId>(m.channels.size()), schema_id, std::string(topic),
                  std::string(message_encoding), metadata};
  detail::put_channel_record(m.current->records, channel);
  id_out = channel.id;
  m.statistics.channel_message_counts[channel.id] = 0;
  m.channels.emplace(channel.id, std::move(channel));
  return {};
}

Status Writer::write(ChannelId channel_id, Timestamp log_time, Timestamp publish_time,
                     std::span<const std::byte> data, std::uint32_t sequence) {
  if (!is_open()) return Status(StatusCode::invalid_argument, "write: writer is not open");
  Impl& m = *impl_;
  if (m.failed.load()) return m.output_status();
  auto count = m.statistics.channel_message_counts.find(channel_id);
  if (count == m.statistics.channel_message_counts.end()) {
    return Status(StatusCode::invalid_argument,
                  "write: unknown channel id " + std::to_string(channel_id));
  }
  Job& job = *m.current;
  const std::uint64_t offset = job.records.size();
  unsigned char head[kMessageRecordHeader];
  head[0] = static_cast<unsigned char>(Opcode::message);
  auto* p = reinterpret_cast<std::byte*>(head);
  detail::write_u64_at(p + 1, 2 + 4 + 8 + 8 + data.size());
  p[9] = static_cast<std::byte>(channel_id & 0xFF);
  p[10] = static_cast<std::byte>(channel_id >> 8);
  detail::write_u32_at(p + 11, sequence);
  detail::write_u64_at(p + 15, log_time);
  detail::write_u64_at(p + 23, publish_time);
  job.records.append(head, sizeof(head));
  job.records.append(data);
  job.index[channel_id].emplace_back(log_time, offset);
  if (job.message_count == 0) {
    job.start = job.end = log_time;
  } else {
    job.start = std::min(job.start, log_time);
    job.end = std::max(job.end, log_time);
  }
  ++job.message_count;

  Statistics& stats = m.statistics;
  if (stats.message_count == 0) {
    stats.message_start_time = stats.message_end_time = log_time;
  } else {
    stats.message_start_time = std::min(stats.message_start_time, log_time);
    stats.message_end_time = std::max(stats.message_end_time, log_time);
  }
  ++stats.message_count;
  ++count->second;
  m.message_bytes += data.size();

  if (job.records.size() >= m.options.chunk_size_bytes) return m.finish_chunk();
  return {};
}

Status Writer::add_metadata(std::string_view name, const KeyValueMap& metadata) {
  if (!is_open()) return Status(StatusCode::invalid_argument, "add_metadata: writer is not open");
  Impl& m = *impl_;
  if (Status s = m.finish_chunk(); !s.ok()) return s;  // keeps file order = call order
  std::unique_ptr<Job> job = m.take_job();
  job->is_metadata = true;
  job->metadata_name = std::string(name);
  detail::put_metadata_record(job->records, Metadata{std::string(name), metadata});
  ++m.statistics.metadata_count;
  return m.submit(std::move(job));
}

Status Writer::flush_chunk() {
  if (!is_open()) return Status(StatusCode::invalid_argument, "flush_chunk: writer is not open");
  return impl_->finish_chunk();
}

Status Writer::close() {
  if (!is_open()) return Status(StatusCode::invalid_argument, "close: writer is not open");
  Impl& m = *impl_;
  Status status = m.finish_chunk();
  m.stop_worker();
  if (status.ok()) status = m.output_status();
  if (status.ok()) {
    Statistics stats = m.statistics;
    stats.schema_count = static_cast<std::uint16_t>(m.schemas.size());
    stats.channel_count = static_cast<std::uint32_t>(m.channels.size());
    stats.chunk_count = m.chunk_index_count;
    detail::TailContent tail{&m.schemas, &m.channels, &m.chunk_index_records, &m.metadata_indexes,
                             stats};
    status = detail::write_tail(m.file, tail, m.options.data_section_crc, m.options.summary_crc);
  }
  Status closed = m.file.close();
  m.bytes_written.store(m.file.position());
  return status.ok() ? closed : status;
}

WriterStatistics Writer::statistics() const {
  WriterStatistics out;
  if (!impl_) return out;
  out.message_count = impl_->statistics.message_count;
  out.message_bytes = impl_->message_bytes;
  out.chunk_count = impl_->chunks_written.load();
  out.file_bytes = impl_->bytes_written.load();
  out.messages_in_file = impl_->messages_in_file.load();
  return out;
}

std::uint64_t Writer::messages_in_file(ChannelId channel) const {
  if (!impl_) return 0;
  std::lock_guard lock(impl_->in_file_mutex);
  auto it = impl_->channel_messages_in_file.find(channel);
  return it == impl_->channel_messages_in_file.end() ? 0 : it->second;
}

}  // namespace avs::mcap
