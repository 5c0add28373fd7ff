// Every learnable number of a model in one flat buffer, with named views.
// One buffer means Adam is one loop, a checkpoint is one array, and a gradient
// check can perturb "everything" by index. Views are (name, offset, rows, cols).
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/tape.h"

namespace jsa {

template <class T>
class Parameters {
 public:
  struct Entry {
    std::string name;
    size_t offset;
    Index rows, cols;
  };
  using Map = Eigen::Map<Block<T>>;
  using ConstMap = Eigen::Map<const Block<T>>;

  // Adds a zero-filled rows x cols parameter; returns its index.
  int add(const std::string& name, Index rows, Index cols);
  int find(const std::string& name) const;  // -1 if absent
  int count() const { return int(entries_.size()); }
  const Entry& entry(int i) const { return entries_[i]; }
  size_t size() const { return value_.size(); }

  Map value(int i) {
    return Map(value_.data() + entries_[i].offset, entries_[i].rows, entries_[i].cols);
  }
  ConstMap value(int i) const {
    return ConstMap(value_.data() + entries_[i].offset, entries_[i].rows, entries_[i].cols);
  }
  Map grad(int i) {
    return Map(grad_.data() + entries_[i].offset, entries_[i].rows, entries_[i].cols);
  }
  std::vector<T>& values() { return value_; }
  const std::vector<T>& values() const { return value_; }
  std::vector<T>& grads() { return grad_; }
  const std::vector<T>& grads() const { return grad_; }
  void zero_grad();

  // Puts parameter i on the tape as a leaf; backward() adds its gradient into grad(i).
  Var on(Tape<T>& t, int i);

  // Binary save/load by name: a loaded file must hold every parameter this set
  // has, with the same shape; extra names in the file are an error too.
  void save(std::ostream& out) const;
  void load(std::istream& in, const std::string& what);

 private:
  std::vector<Entry> entries_;
  std::vector<T> value_, grad_;
};

}  // namespace jsa
