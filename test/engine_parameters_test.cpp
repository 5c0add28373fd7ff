// Tests of engine/parameters.h: named views on one flat buffer, gradients
// flowing from the tape into the buffer, and save/load (round trip, and every
// kind of bad file throwing jsa::InputError).
#include <catch2/catch.hpp>
#include <sstream>

#include "engine/ops.h"
#include "engine/parameters.h"

namespace jsa {
namespace {

Parameters<float> two_layer() {
  Parameters<float> p;
  p.add("layer0.weight", 2, 3);
  p.add("layer0.bias", 1, 3);
  p.add("layer1.weight", 3, 1);
  for (size_t i = 0; i < p.size(); ++i) p.values()[i] = 0.5f * float(i) - 1.0f;
  return p;
}

std::string saved(const Parameters<float>& p) {
  std::ostringstream out;
  p.save(out);
  return out.str();
}

}  // namespace

TEST_CASE("parameters are named views on one flat buffer", "[parameters]") {
  Parameters<float> p = two_layer();
  CHECK(p.count() == 3);
  CHECK(p.size() == 6 + 3 + 3);
  CHECK(p.find("layer0.bias") == 1);
  CHECK(p.find("nope") == -1);
  CHECK(p.entry(2).offset == 9);
  p.value(1)(0, 2) = 42.0f;
  CHECK(p.values()[6 + 2] == 42.0f);
  // Row-major view: (i, j) of a 2x3 at offset + 3 i + j.
  CHECK(p.value(0)(1, 0) == p.values()[3]);
  CHECK_THROWS_AS(p.add("layer0.bias", 1, 1), InternalError);
  CHECK_THROWS_AS(p.add("empty", 0, 3), InternalError);
}

TEST_CASE("on() hands the tape's gradient to the flat buffer", "[parameters]") {
  Parameters<double> p;
  const int w = p.add("w", 2, 2);
  p.values() = {1, 2, 3, 4};
  Tape<double> t;
  Block<double> x(1, 2);
  x << 1, -1;
  // loss = sum(x W) twice from two leaves of the same parameter: gradients add.
  for (int pass = 0; pass < 2; ++pass) {
    t.clear();
    p.zero_grad();
    Var a = linear(t, t.constant(x), p.on(t, w), Var{});
    Var b = linear(t, t.constant(x), p.on(t, w), Var{});
    t.backward(sum(t, add(t, a, b)));
    // d/dW sum(x W) = x^T 1 = [[1, 1], [-1, -1]]; twice.
    CHECK(p.grads() == std::vector<double>{2, 2, -2, -2});
  }
}

TEST_CASE("a tape with a gradient buffer of its own leaves the parameters' alone", "[parameters]") {
  Parameters<double> p;
  p.add("a", 1, 2);
  const int w = p.add("w", 2, 2);
  p.values() = {9, 9, 1, 2, 3, 4};
  Block<double> x(1, 2);
  x << 1, -1;
  std::vector<double> own(p.size(), 5.0);  // not zeroed: on() adds, the caller zeroes
  Tape<double> t;
  t.set_parameter_grads(&own);
  p.zero_grad();
  t.backward(sum(t, linear(t, t.constant(x), p.on(t, w), Var{})));
  CHECK(own == std::vector<double>{5, 5, 6, 6, 4, 4});  // w's rows at its offset, 2 on
  CHECK(p.grads() == std::vector<double>(6, 0.0));
  // A buffer of another layout is an error, not a write past its end.
  std::vector<double> short_buffer(3, 0.0);
  t.clear();
  t.set_parameter_grads(&short_buffer);
  const Var loss = sum(t, linear(t, t.constant(x), p.on(t, w), Var{}));
  CHECK_THROWS_WITH(t.backward(loss), Catch::Contains("gradient buffer of 3 numbers"));
}

TEST_CASE("save then load restores every value", "[parameters][io]") {
  const Parameters<float> a = two_layer();
  Parameters<float> b;
  b.add("layer0.weight", 2, 3);
  b.add("layer0.bias", 1, 3);
  b.add("layer1.weight", 3, 1);
  std::istringstream in(saved(a));
  b.load(in, "test.bin");
  CHECK(b.values() == a.values());

  // Order in the file need not match the order of add().
  Parameters<float> c;
  c.add("layer1.weight", 3, 1);
  c.add("layer0.weight", 2, 3);
  c.add("layer0.bias", 1, 3);
  std::istringstream in2(saved(a));
  c.load(in2, "test.bin");
  CHECK(c.value(0) == a.value(2));
  CHECK(c.value(1) == a.value(0));
}

TEST_CASE("bad parameter files throw InputError naming the file", "[parameters][io][errors]") {
  const std::string good = saved(two_layer());
  auto load_into = [](Parameters<float>& p, const std::string& bytes) {
    std::istringstream in(bytes);
    p.load(in, "model.bin");
  };
  SECTION("wrong shape") {
    Parameters<float> p;
    p.add("layer0.weight", 3, 2);  // transposed
    p.add("layer0.bias", 1, 3);
    p.add("layer1.weight", 3, 1);
    CHECK_THROWS_AS(load_into(p, good), InputError);
    CHECK_THROWS_WITH(load_into(p, good),
                      Catch::Contains("model.bin") && Catch::Contains("layer0.weight"));
  }
  SECTION("unknown name") {
    Parameters<float> p;
    p.add("layer0.weight", 2, 3);
    p.add("layer0.bias", 1, 3);
    p.add("layer2.weight", 3, 1);
    CHECK_THROWS_AS(load_into(p, good), InputError);
    CHECK_THROWS_WITH(load_into(p, good), Catch::Contains("layer1.weight"));
  }
  SECTION("different parameter count") {
    Parameters<float> p;
    p.add("layer0.weight", 2, 3);
    CHECK_THROWS_AS(load_into(p, good), InputError);
  }
  SECTION("truncated anywhere") {
    for (size_t cut :
         {size_t(0), size_t(2), size_t(4), size_t(10), good.size() / 2, good.size() - 1}) {
      Parameters<float> p = two_layer();
      INFO("cut at byte " << cut << " of " << good.size());
      CHECK_THROWS_AS(load_into(p, good.substr(0, cut)), InputError);
    }
  }
  SECTION("a name twice (so another is missing)") {
    // count = 2, then "a" 1x1 twice, written field by field as save() does.
    std::ostringstream out;
    auto put = [&](const void* q, size_t n) {
      out.write(static_cast<const char*>(q), std::streamsize(n));
    };
    const uint32_t count = 2, len = 1;
    const int64_t one = 1;
    const float value = 3.0f;
    put(&count, sizeof count);
    for (int k = 0; k < 2; ++k) {
      put(&len, sizeof len);
      put("a", 1);
      put(&one, sizeof one);
      put(&one, sizeof one);
      put(&value, sizeof value);
    }
    Parameters<float> p;
    p.add("a", 1, 1);
    p.add("b", 1, 1);
    CHECK_THROWS_AS(load_into(p, out.str()), InputError);
    CHECK_THROWS_WITH(load_into(p, out.str()), Catch::Contains("twice"));
  }
  SECTION("corrupt name length") {
    std::string bad = good;
    bad[4] = char(0xff);  // first name length becomes > 4096
    bad[5] = char(0xff);
    Parameters<float> p = two_layer();
    CHECK_THROWS_AS(load_into(p, bad), InputError);
  }
}

}  // namespace jsa
