/* Radau IIA of order 5: scipy's constants, GENERATED, do not edit.
 *
 * python -m posturelab.simulation.compiled._codegen writes this file from
 * scipy.integrate._ivp.radau (_codegen/radau_c.py); pl_radau.c includes it. */
#ifndef PL_RADAU_H
#define PL_RADAU_H

/* the nodes of a step (0, c_1, c_2, 1): where its inputs are taken */
static const double NODES[4] = {0.0, 0.15505102572168222, 0.6449489742783178, 1.0};
/* the eigenvalues of the inverse Radau matrix, μ_r and μ_c = MU_CRE + i·MU_CIM */
static const double MU_REAL = 3.637834252744496;
static const double MU_CRE = 2.6810828736277523, MU_CIM = -3.050430199247411;
/* the weights of the embedded error estimate */
static const double E1 = -10.048809399827414, E2 = 1.382142733160748, E3 = -0.3333333333333333;
/* the dense output Q = Zᵀ P (the collocation polynomial) */
static const double P[3][3] = {
    {10.048809399827414, -25.62959144707664, 15.580782047249224},
    {-1.382142733160748, 10.296258113743303, -8.914115380582556},
    {0.3333333333333333, -2.6666666666666665, 3.3333333333333335}};
/* the transformation that diagonalises the inverse Radau matrix, and its inverse */
static const double T[3][3] = {
    {0.09443876248897524, -0.1412552950209542, 0.03002919410514742},
    {0.2502131229653333, 0.20412935229379994, -0.3829421127572619},
    {1.0, 1.0, 0.0}};
static const double TI[3][3] = {
    {4.178718591551904, 0.32768282076106237, 0.5233764454994495},
    {-4.178718591551904, -0.32768282076106237, 0.47662355450055044},
    {0.5028726349457868, -2.571926949855605, 0.5960392048282249}};

#endif
