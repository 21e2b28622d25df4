#include "nodes/hull_node.h"
#include "nodes/node_main.h"

int main(int argc, char** argv) {
  return sift_hull::runNode<sift_hull::HullNode>(argc, argv, "hull_node");
}
