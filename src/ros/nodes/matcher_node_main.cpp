#include "nodes/matcher_node.h"
#include "nodes/node_main.h"

int main(int argc, char** argv) {
  return sift_hull::runNode<sift_hull::MatcherNode>(argc, argv, "matcher_node");
}
