#pragma once
/// @file
/// How a receiver answers requests idempotently: it remembers the answers it gave to the last
/// `capacity` request ids, so that a repeated request (the sender's retry, or a datagram the
/// network duplicated or held back) gets its first answer again and changes nothing. Used by the
/// registration server (SESSION_CONTROL: a COMPUTE's REGISTRATION, nothing for START / RESET / STOP)
/// and the headset (REQUEST_TRIAL: the ALIGNMENT_TRIAL it published).
///
/// Request id 0 means "no id" (contract: session_control_t.request_id): it is never remembered, so
/// such a request is acted on every time. A receiver remembers a request only once it acted on it;
/// a refused request is not remembered, so its retry is judged afresh (e.g. a REQUEST_TRIAL refused
/// before the robot state was known succeeds when retried after it).
///
/// Threading: not synchronised; one thread (the Process::Run() thread).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>

namespace orbed {

template <class Answer>
class RecentAnswers {
 public:
  explicit RecentAnswers(std::size_t capacity = 64) : capacity_(capacity) {}

  /// The answer given to `request_id`, or nullptr if it is not remembered (id 0 never is).
  const Answer* Find(std::int64_t request_id) const {
    if (request_id == 0) return nullptr;
    for (const auto& [id, answer] : answers_)
      if (id == request_id) return &answer;
    return nullptr;
  }

  /// Remembers `answer` for `request_id` (id 0: ignored), forgetting the oldest beyond capacity.
  void Remember(std::int64_t request_id, Answer answer) {
    if (request_id == 0 || capacity_ == 0) return;
    answers_.emplace_back(request_id, std::move(answer));
    if (answers_.size() > capacity_) answers_.pop_front();
  }

  std::size_t size() const { return answers_.size(); }

 private:
  std::size_t capacity_;
  std::deque<std::pair<std::int64_t, Answer>> answers_;
};

}  // namespace orbed
