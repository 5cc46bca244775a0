#pragma once
/// The constraints and inputs of a linkage (core/planar/system.hpp) in block-triangular form, and
/// the evaluations that use it.
///
/// The square system of the constraint rows and the inputs, G q̇ = b, is sparse: a row involves
/// at most three nodes. Permuted to block-triangular form (Dulmage–Mendelsohn: a perfect matching
/// of rows to coordinates, then the strongly connected components of the rows' dependencies in
/// the order that puts every block after the blocks it depends on) it is solved block by block,
/// each block with the coordinates of the blocks before it known. For the linkages people build
/// the blocks are Assur's: a crank's tip placed from its pivot and the input's angle, a dyad's
/// middle node from its two outer nodes (two circles), a slider's node on a frame guide (a circle
/// and a line), a further node of a link from its element's nodes; each of those has a closed
/// form, exact to round-off without iterations. Any other block (a triad, a ternary link's
/// element node held through a further node) is solved by Newton's method on its own rows.
///
/// The positions, the rates, the accelerations (forward substitution over the blocks) and the
/// multipliers (backward substitution with Gᵀ) then need no factorisation of the whole system.
/// This is the driven sweep's route (core/planar/simulate.cpp), and solve_position()'s for a plan
/// of closed forms whose branch the guess tells (one-instant calls, free runs' reduced route;
/// prime_closed_blocks()). Where a block is poorly conditioned (a dead centre near), a circle
/// pair no longer meets, or Newton's method on a block does not converge, place_by_blocks()
/// declines and the caller takes the general route (core/planar/dynamics.hpp, solve_position()),
/// which decides whether the position is singular and says so. docs/performance.md ("The general
/// planar engine") has the measurements.
///
/// Internal to core/planar.
#include <Eigen/Core>
#include <vector>

#include "core/planar/system.hpp"

namespace bd::core::planar {
class Model;
class Workspace;
}  // namespace bd::core::planar

namespace bd::core::planar::detail {

/// Records the assembly branch of the positions in ws.instant.x: per block, the side of the line
/// through the known nodes on which a dyad's node lies, the side of the foot of the perpendicular
/// on which a guide's node lies, a general block's determinant sign. place_by_blocks() keeps
/// those; call after every position the general route solved.
void prime_blocks(const Model& model, Workspace& ws);

/// For a plan of closed forms (BlockPlan::closed): the branch of each dyad and guide as
/// prime_blocks() records it, read from positions `x` near the solution (a guess, such as the last
/// instant's) rather than from a solved position. Returns false where the plan is not closed or a
/// block's node in `x` lies within a sine of 1e-2 of the line that divides its branches (x does
/// not tell the branch clearly; the general route's Newton iterations decide); the branches are
/// then recorded in part only, so place_by_blocks() needs prime_blocks() or this first again.
bool prime_closed_blocks(const Model& model, Workspace& ws, const NodeVectors& x);

/// What place_by_blocks() did.
enum class Placement {
  kPlaced,  // every node, to round-off, and the blocks' factorisations there
  /// every node placed by the closed forms on the branches prime_blocks() recorded (in
  /// ws.instant.x), but a block's rows are too close to singular (their sine below 1e-2) for
  /// round-off: a guess on the right branch for the general route, not a solution
  kIllConditioned,
  /// no plan, two circles that do not meet, a general block whose Newton's method does not
  /// converge, whose determinant changed sign or whose conditioning is poor
  kDeclined,
};
/// The positions at `inputs` block by block (the general blocks by Newton's method from `guess`,
/// which closed-form plans do not read), on the branch prime_blocks() recorded, and the blocks'
/// factorisations there. Sets ws.instant.x and .input and ws.by_blocks where it places
/// (kPlaced); otherwise it changes nothing the general route reads but ws.instant.x. Each dyad
/// and guide it reaches records its closure margin in ws.block_margin: the square of its node's
/// distance from the line dividing its branches (h² = r² - a², a along that line), 0 at a limit
/// position, where the two circles (or the circle and the guide) just touch.
Placement place_by_blocks(const Model& model, Workspace& ws, const NodeVectors& guess,
                          const std::vector<double>& inputs);

/// After place_by_blocks(): the determinant of the whole Jacobian G, from the blocks' (as the
/// general route's factorisation gives it, to round-off).
double block_determinant(const Model& model, const Workspace& ws);

/// After place_by_blocks(): x = G⁻¹ b by forward substitution over the blocks (x may not be b).
void block_solve(const Model& model, Workspace& ws, const Eigen::VectorXd& b, Eigen::VectorXd& x);
/// After place_by_blocks(): x = G⁻ᵀ b by backward substitution (x may not be b).
void block_solve_transpose(const Model& model, Workspace& ws, const Eigen::VectorXd& b,
                           Eigen::VectorXd& x);

/// After place_by_blocks() on a plan of closed forms (BlockPlan::closed): the nodes' velocities
/// and accelerations for the inputs' rates and accelerations, block by block from each block's
/// own geometry (a crank's tip turning about its pivot; a dyad's node from its two rows
/// (P - A)·(v_P - v_A) = 0, (P - B)·(v_P - v_B) = 0 and their derivatives; a guide's node along
/// its guide; a further node as its element's nodes weigh it), without the Jacobian. Sets
/// ws.instant.v, .a, .input_rate and .input_acceleration (not ws.qd and ws.qdd: nothing after
/// reads them).
void closed_form_kinematics(const Model& model, Workspace& ws, const std::vector<double>& rates,
                            const std::vector<double>& accelerations);

}  // namespace bd::core::planar::detail
