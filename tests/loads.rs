//! Analytic load terms against numerical quadrature of the point Green function.
