// Status / Result: the error-as-value plumbing every stage relies on.
#include <catch2/catch.hpp>

#include "spherekit/status.h"

using namespace spherekit;

namespace {
Status fails() { return Status(ErrorCode::InvalidInput, "bad mesh"); }
Status propagates() {
  SPHEREKIT_RETURN_IF_ERROR(fails());
  return Status(ErrorCode::Internal, "not reached");
}
Result<int> half(int x) {
  if (x % 2) return Status(ErrorCode::InvalidArgument, "odd");
  return x / 2;
}
Result<int> quarter(int x) {
  SPHEREKIT_ASSIGN_OR_RETURN(int h, half(x));
  return half(h);
}
}  // namespace

TEST_CASE("status codes have names and distinct exit classes", "[param][status]") {
  CHECK(std::string(error_code_name(ErrorCode::InvalidInput)) == "InvalidInput");
  CHECK(error_code_exit_code(ErrorCode::Ok) == 0);
  CHECK(error_code_exit_code(ErrorCode::Cancelled) == 130);
  CHECK(error_code_exit_code(ErrorCode::InvalidInput) != error_code_exit_code(ErrorCode::SolverFailed));
  CHECK(error_code_exit_code(ErrorCode::IoError) != error_code_exit_code(ErrorCode::InvalidInput));
}

TEST_CASE("errors propagate with their code and message", "[param][status]") {
  Status s = propagates();
  CHECK_FALSE(s.ok());
  CHECK(s.code() == ErrorCode::InvalidInput);
  CHECK(s.with_context("m.obj").message() == "m.obj: bad mesh");
  CHECK(Status().with_context("x").ok());
  auto q = quarter(8);
  REQUIRE(q.ok());
  CHECK(*q == 2);
  auto bad = quarter(6);  // 6 -> 3 -> odd
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.status().code() == ErrorCode::InvalidArgument);
  CHECK(quarter(8).status().ok());
}
