#include "engine/parameters.h"

#include <cstdint>
#include <istream>
#include <ostream>

namespace jsa {

template <class T>
int Parameters<T>::add(const std::string& name, Index rows, Index cols) {
  JSA_CHECK(find(name) < 0, "parameter '" << name << "' added twice");
  JSA_CHECK(rows > 0 && cols > 0, "parameter '" << name << "' is empty");
  entries_.push_back({name, value_.size(), rows, cols});
  value_.resize(value_.size() + size_t(rows * cols), T(0));
  grad_.resize(value_.size(), T(0));
  return int(entries_.size()) - 1;
}

template <class T>
int Parameters<T>::find(const std::string& name) const {
  for (size_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].name == name) return int(i);
  return -1;
}

template <class T>
void Parameters<T>::zero_grad() {
  std::fill(grad_.begin(), grad_.end(), T(0));
}

template <class T>
Var Parameters<T>::on(Tape<T>& t, int i) {
  Var v = t.variable(value(i));  // copied straight into the node (no temporary block)
  // dθ_i += d(node): the leaf hands its gradient to the flat buffer, or to the
  // tape's own buffer of the same layout when it has one (Tape::set_parameter_grads).
  t.on_backward(v, [this, i](Tape<T>& t, Var v) {
    std::vector<T>* own = t.parameter_grads();
    if (!own) {
      grad(i) += t.grad(v);
      return;
    }
    JSA_CHECK(own->size() == grad_.size(), "a tape's gradient buffer of "
                                               << own->size() << " numbers for " << grad_.size()
                                               << " parameters");
    const Entry& e = entries_[size_t(i)];
    Map(own->data() + e.offset, e.rows, e.cols) += t.grad(v);
  });
  return v;
}

// Layout: u32 count, then per entry: u32 name length, name, i64 rows, i64 cols,
// rows*cols values of T (little-endian host order; checkpoints add a checksum).
template <class T>
void Parameters<T>::save(std::ostream& out) const {
  auto put = [&](const void* p, size_t n) {
    out.write(static_cast<const char*>(p), std::streamsize(n));
  };
  const uint32_t count = uint32_t(entries_.size());
  put(&count, sizeof count);
  for (const Entry& e : entries_) {
    const uint32_t len = uint32_t(e.name.size());
    const int64_t r = e.rows, c = e.cols;
    put(&len, sizeof len);
    put(e.name.data(), len);
    put(&r, sizeof r);
    put(&c, sizeof c);
    put(value_.data() + e.offset, sizeof(T) * size_t(r * c));
  }
}

template <class T>
void Parameters<T>::load(std::istream& in, const std::string& what) {
  auto get = [&](void* p, size_t n) {
    in.read(static_cast<char*>(p), std::streamsize(n));
    if (size_t(in.gcount()) != n) throw InputError(what + ": truncated parameter block");
  };
  uint32_t count = 0;
  get(&count, sizeof count);
  if (count != entries_.size())
    throw InputError(what + ": holds " + std::to_string(count) + " parameters, the model has " +
                     std::to_string(entries_.size()));
  // The count matches, so every parameter is present iff no name repeats.
  std::vector<bool> seen(entries_.size(), false);
  for (uint32_t k = 0; k < count; ++k) {
    uint32_t len = 0;
    get(&len, sizeof len);
    if (len > 4096) throw InputError(what + ": parameter name too long (corrupt file?)");
    std::string name(len, '\0');
    get(name.data(), len);
    int64_t r = 0, c = 0;
    get(&r, sizeof r);
    get(&c, sizeof c);
    const int i = find(name);
    if (i < 0) throw InputError(what + ": unknown parameter '" + name + "'");
    if (seen[i])
      throw InputError(what + ": parameter '" + name + "' appears twice (corrupt file?)");
    seen[i] = true;
    if (r != entries_[i].rows || c != entries_[i].cols)
      throw InputError(what + ": parameter '" + name + "' is " + std::to_string(r) + "x" +
                       std::to_string(c) + ", the model wants " + std::to_string(entries_[i].rows) +
                       "x" + std::to_string(entries_[i].cols));
    get(value_.data() + entries_[i].offset, sizeof(T) * size_t(r * c));
  }
}

template class Parameters<float>;
template class Parameters<double>;

}  // namespace jsa
