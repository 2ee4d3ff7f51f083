// Bipartite Location Graph (thesis §3.2.3, Figure 3.10). See location_graph.h.
#include "core/svrc/location_graph.h"

#include <map>
#include <tuple>

namespace svrc::refine {

LocationGraph::List& LocationGraph::CellList(MeshId mesh, uint32_t cell) {
  if (cell_lists_.size() <= mesh.value()) {
    cell_lists_.resize(mesh.value() + 1);
    unresolved_.resize(mesh.value() + 1);
  }
  std::vector<List>& lists = cell_lists_[mesh.value()];
  if (lists.size() <= cell) {
    lists.resize(cell + 1);
    unresolved_[mesh.value()].resize(cell + 1, 0);
  }
  return lists[cell];
}

const LocationGraph::List* LocationGraph::FindCellList(MeshId mesh, uint32_t cell) const {
  if (cell_lists_.size() <= mesh.value() || cell_lists_[mesh.value()].size() <= cell) return nullptr;
  return &cell_lists_[mesh.value()][cell];
}

LocationGraph::List& LocationGraph::ObjectList(LocationObject object) {
  std::vector<List>& lists = object.kind == ObjectKind::kBall ? ball_lists_ : collar_lists_;
  if (lists.size() <= object.id) lists.resize(object.id + 1);
  return lists[object.id];
}

const LocationGraph::List* LocationGraph::FindObjectList(LocationObject object) const {
  const std::vector<List>& lists = object.kind == ObjectKind::kBall ? ball_lists_ : collar_lists_;
  return lists.size() <= object.id ? nullptr : &lists[object.id];
}

uint32_t LocationGraph::Find(MeshId mesh, uint32_t cell, LocationObject object) const {
  // Walk the shorter of the two lists: early in a run one cell can hold
  // thousands of unresolved points, and an input object can be linked to many
  // cells; the other list is then short (bounded ply, Lemma 6).
  const List* cl = FindCellList(mesh, cell);
  const List* ol = FindObjectList(object);
  if (cl == nullptr || ol == nullptr) return kNil;
  if (cl->size <= ol->size) {
    for (uint32_t l = cl->head; l != kNil; l = links_[l].next_cell) {
      if (links_[l].object == object) return l;
    }
  } else {
    for (uint32_t l = ol->head; l != kNil; l = links_[l].next_obj) {
      if (links_[l].cell == cell && links_[l].mesh == mesh) return l;
    }
  }
  return kNil;
}

AddLinkResult LocationGraph::AddLink(MeshId mesh, uint32_t cell, LocationObject object,
                                     const LinkFacts& facts, BallStore* balls) {
  AddLinkResult result;
  if (Find(mesh, cell, object) != kNil) {
    ++stats_.duplicates_refused;
    return result;
  }
  uint32_t l;
  if (free_head_ != kNil) {
    l = free_head_;
    free_head_ = links_[l].next_obj;
  } else {
    l = static_cast<uint32_t>(links_.size());
    links_.emplace_back();
  }
  Link& link = links_[l];
  link = Link{};
  link.object = object;
  link.mesh = mesh;
  link.cell = cell;
  link.unresolved = facts.unresolved;

  List& cl = CellList(mesh, cell);
  link.prev_cell = cl.tail;
  if (cl.tail != kNil) links_[cl.tail].next_cell = l; else cl.head = l;
  cl.tail = l;
  ++cl.size;
  List& ol = ObjectList(object);
  link.prev_obj = ol.tail;
  if (ol.tail != kNil) links_[ol.tail].next_obj = l; else ol.head = l;
  ol.tail = l;
  ++ol.size;
  ++num_links_;
  ++stats_.links_added;
  result.link = LinkId(l);

  if (facts.unresolved) {
    uint32_t& count = unresolved_[mesh.value()][cell];
    result.cell_became_unresolved = (count == 0);
    ++count;
  }
  // Figure 3.10: a ConfBall with the cell's vertex strictly inside is
  // encroached; native vertices trigger at once, others on the second,
  // different encroacher.
  if (object.kind == ObjectKind::kBall && facts.encroaches && balls != nullptr) {
    const BallId b(object.id);
    if (balls->Kind(b) == BallKind::kConf) {
      result.encroach = balls->RecordEncroacher(b, facts.vertex_point, facts.native);
    }
  }
  return result;
}

void LocationGraph::RemoveLink(LinkId id) {
  const uint32_t l = id.value();
  Link& link = links_[l];
  if (link.cell == kNil) return;
  List& cl = cell_lists_[link.mesh.value()][link.cell];
  if (link.prev_cell != kNil) links_[link.prev_cell].next_cell = link.next_cell; else cl.head = link.next_cell;
  if (link.next_cell != kNil) links_[link.next_cell].prev_cell = link.prev_cell; else cl.tail = link.prev_cell;
  List& ol = ObjectList(link.object);
  if (link.prev_obj != kNil) links_[link.prev_obj].next_obj = link.next_obj; else ol.head = link.next_obj;
  if (link.next_obj != kNil) links_[link.next_obj].prev_obj = link.prev_obj; else ol.tail = link.prev_obj;
  --cl.size;
  --ol.size;
  if (link.unresolved) --unresolved_[link.mesh.value()][link.cell];
  link.cell = kNil;
  link.prev_cell = link.next_cell = link.prev_obj = kNil;
  link.next_obj = free_head_;
  free_head_ = l;
  --num_links_;
  ++stats_.links_removed;
}

bool LocationGraph::RemoveLink(MeshId mesh, uint32_t cell, LocationObject object) {
  const uint32_t l = Find(mesh, cell, object);
  if (l == kNil) return false;
  RemoveLink(LinkId(l));
  return true;
}

void LocationGraph::RemoveCellLinks(MeshId mesh, uint32_t cell, std::vector<LocationObject>* removed) {
  const List* list = FindCellList(mesh, cell);
  if (list == nullptr) return;
  while (list->head != kNil) {
    const uint32_t l = list->head;
    if (removed != nullptr) removed->push_back(links_[l].object);
    RemoveLink(LinkId(l));
  }
}

void LocationGraph::RemoveObjectLinks(LocationObject object, MeshId mesh, std::vector<uint32_t>* cells) {
  const List* list = FindObjectList(object);
  if (list == nullptr) return;
  uint32_t l = list->head;
  while (l != kNil) {
    const uint32_t next = links_[l].next_obj;
    if (!mesh.valid() || links_[l].mesh == mesh) {
      if (cells != nullptr) cells->push_back(links_[l].cell);
      RemoveLink(LinkId(l));
    }
    l = next;
  }
}

void LocationGraph::BallsOf(MeshId mesh, uint32_t cell, std::vector<BallId>* out) const {
  const List* list = FindCellList(mesh, cell);
  if (list == nullptr) return;
  for (uint32_t l = list->head; l != kNil; l = links_[l].next_cell) {
    if (links_[l].object.kind == ObjectKind::kBall) out->push_back(BallId(links_[l].object.id));
  }
}

void LocationGraph::ObjectsOf(MeshId mesh, uint32_t cell, std::vector<LocationObject>* out) const {
  const List* list = FindCellList(mesh, cell);
  if (list == nullptr) return;
  for (uint32_t l = list->head; l != kNil; l = links_[l].next_cell) out->push_back(links_[l].object);
}

void LocationGraph::CellsOf(LocationObject object, MeshId mesh, std::vector<uint32_t>* out) const {
  const List* list = FindObjectList(object);
  if (list == nullptr) return;
  for (uint32_t l = list->head; l != kNil; l = links_[l].next_obj) {
    if (links_[l].mesh == mesh) out->push_back(links_[l].cell);
  }
}

bool LocationGraph::IsLinked(MeshId mesh, uint32_t cell, LocationObject object) const {
  return Find(mesh, cell, object) != kNil;
}

uint32_t LocationGraph::NumUnresolved(MeshId mesh, uint32_t cell) const {
  if (unresolved_.size() <= mesh.value() || unresolved_[mesh.value()].size() <= cell) return 0;
  return unresolved_[mesh.value()][cell];
}

bool LocationGraph::Validate() const {
  // Walk every cell list and every object list; each live link must be seen
  // exactly once from each side with consistent back pointers.
  std::vector<uint8_t> seen_cell(links_.size(), 0), seen_obj(links_.size(), 0);
  std::map<std::tuple<uint32_t, uint32_t, uint8_t, uint32_t>, int> pairs;
  uint32_t count = 0;
  for (uint32_t m = 0; m < cell_lists_.size(); ++m) {
    for (uint32_t c = 0; c < cell_lists_[m].size(); ++c) {
      const List& list = cell_lists_[m][c];
      uint32_t prev = kNil, unresolved = 0;
      for (uint32_t l = list.head; l != kNil; l = links_[l].next_cell) {
        const Link& link = links_[l];
        if (link.cell != c || link.mesh.value() != m || link.prev_cell != prev) return false;
        if (seen_cell[l]++) return false;
        if (link.unresolved) ++unresolved;
        if (++pairs[{m, c, static_cast<uint8_t>(link.object.kind), link.object.id}] > 1) return false;
        prev = l;
        ++count;
      }
      if (list.tail != prev || unresolved_[m][c] != unresolved) return false;
    }
  }
  for (int kind = 0; kind < 2; ++kind) {
    const std::vector<List>& lists = kind == 0 ? ball_lists_ : collar_lists_;
    for (uint32_t o = 0; o < lists.size(); ++o) {
      uint32_t prev = kNil;
      for (uint32_t l = lists[o].head; l != kNil; l = links_[l].next_obj) {
        const Link& link = links_[l];
        if (link.cell == kNil || static_cast<int>(link.object.kind) != kind || link.object.id != o ||
            link.prev_obj != prev) {
          return false;
        }
        if (seen_obj[l]++) return false;
        prev = l;
      }
      if (lists[o].tail != prev) return false;
    }
  }
  for (uint32_t l = 0; l < links_.size(); ++l) {
    const bool live = links_[l].cell != kNil;
    if (live != (seen_cell[l] == 1) || live != (seen_obj[l] == 1)) return false;
  }
  return count == num_links_;
}

}  // namespace svrc::refine
